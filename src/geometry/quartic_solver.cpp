// Closed-form real roots of polynomials of degree <= 4, made robust (see docs/solver.md).
//
// Pipeline shared by the three entry points:
//   1. reject non-finite input; an exactly zero constant term gives the exact root 0; the
//      largest roots are dropped ("at infinity") when the leading coefficient is negligible;
//      quadratics with coefficients in a safe range go straight to the stable formula;
//   2. candidates in closed form (quartic_closed_form.cpp): each quadratic factor yields two
//      simple candidates, nothing (complex pair), or, when its discriminant is zero up to the
//      factorisation's rounding, a "pair centre";
//   3. pair centres (and clusters of close candidates) are settled on the input polynomial
//      itself: critical point of p, and the sign and size of p there;
//   4. Newton polishing on the input polynomial inside each candidate's cell, verification of
//      the residual, sorting and removal of duplicates.
#include "geometry/quartic_solver.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "geometry/quartic_closed_form.h"

namespace lat {
namespace {

using detail::Candidate;
using detail::candidates;
using detail::discriminant;
using detail::kEps;
using detail::kInf;
using detail::newton_polygon;

// |p(x)| <= kResidual * eps * sum_k |c_k x^k| means p(x) = 0 up to the rounding of evaluating
// p at x (Horner for degree 4 is within about 8 eps * sum, half an ulp of x adds <= 2 eps * sum).
constexpr double kResidual = 32.0;
// The group of largest roots is dropped ("at infinity") when the leading coefficient is below
// eps times the largest one and the dropped coefficients change the other roots by less than
// 2^-kDropLog2 relative, i.e. below the rounding of the coefficients (see solve()).
constexpr double kDropLog2 = 52.0;
// A critical point where |p| <= kDouble * eps * sum |c_k x^k| is a double root: the rounding
// of p there is within that. Pairs further apart are split (see resolve_pair).
constexpr double kDouble = 8.0;
// Candidates closer than this (relative) form one cluster (near-double pair or triple root).
constexpr double kCloseGap = 1e-6;
// Polished roots closer than this (relative) are the same root found twice.
constexpr double kSameRoot = 1e-13;
constexpr int kMaxNewton = 16;

// p(x), p'(x) and sum_k |c_k| |x|^k (the scale of p's rounding error) by Horner.
inline void eval(const double* c, int n, double x, double& p, double& dp, double& mag) {
    p = c[n];
    dp = 0.0;
    mag = std::abs(c[n]);
    const double ax = std::abs(x);
    for (int k = n - 1; k >= 0; --k) {
        dp = dp * x + p;
        p = p * x + c[k];
        mag = mag * ax + std::abs(c[k]);
    }
}

// p'(x) and p''(x).
inline void eval_derivs(const double* c, int n, double x, double& dp, double& ddp) {
    double p = c[n];
    dp = 0.0;
    ddp = 0.0;
    for (int k = n - 1; k >= 0; --k) {
        ddp = ddp * x + dp;
        dp = dp * x + p;
        p = p * x + c[k];
    }
    ddp *= 2.0;
}

inline bool is_root(const double* c, int n, double x) {
    double p, dp, mag;
    eval(c, n, x, p, dp, mag);
    return std::abs(p) <= kResidual * kEps * mag;
}

// Newton on p from x inside the open bracket (lo, hi). Stops when |p| is at its rounding
// floor, when the step stops shrinking (the same floor, seen from the steps) or would leave
// the bracket (it would head for another root); the last accepted iterate is returned.
double polish(const double* c, int n, double x, double lo, double hi) {
    double prev = kInf;
    for (int it = 0; it < kMaxNewton; ++it) {
        double p, dp, mag;
        eval(c, n, x, p, dp, mag);
        // At the rounding floor of p the step is noise (and huge where p' ~ 0, in a cluster).
        if (std::abs(p) <= kEps * mag || dp == 0.0) break;
        const double step = p / dp;
        if (!(std::abs(step) < prev)) break;
        const double nx = x - step;
        if (!(nx > lo && nx < hi) || nx == x) break;
        x = nx;
        prev = std::abs(step);
    }
    return x;
}

// Settles a near-double pair around m on the input polynomial: finds the critical point xc of
// p in (lo, hi) and decides from p(xc) and p''(xc): |p(xc)| at rounding level -> one double
// root; p(xc) of the sign opposite to p'' -> two real roots; otherwise a complex pair.
int resolve_pair(const double* c, int n, double m, double lo, double hi, double* out) {
    double x = m, prev = kInf;
    for (int it = 0; it < kMaxNewton; ++it) {
        double dp, ddp;
        eval_derivs(c, n, x, dp, ddp);
        if (dp == 0.0 || ddp == 0.0) break;
        const double step = dp / ddp;
        if (!(std::abs(step) < prev)) break;
        const double nx = x - step;
        if (!(nx > lo && nx < hi) || nx == x) break;
        x = nx;
        prev = std::abs(step);
    }
    double p, dp, mag, ddp;
    eval(c, n, x, p, dp, mag);
    if (std::abs(p) <= kDouble * kEps * mag) {
        out[0] = x;
        return 1;
    }
    eval_derivs(c, n, x, dp, ddp);
    if (ddp == 0.0 || (p < 0.0) == (ddp < 0.0)) return 0;  // signs: the product may underflow
    // Two real roots near x -/+ h (quadratic model of p around its critical point).
    const double h = std::sqrt(-2.0 * p / ddp);
    double left = x - h, right = x + h;
    if (!(left > lo)) left = std::isfinite(lo) ? 0.5 * (lo + x) : x - 2.0 * std::abs(x) - 1.0;
    if (!(right < hi)) right = std::isfinite(hi) ? 0.5 * (x + hi) : x + 2.0 * std::abs(x) + 1.0;
    int k = 0;
    const double r0 = polish(c, n, left, lo, x);
    if (is_root(c, n, r0)) out[k++] = r0;
    const double r1 = polish(c, n, right, x, hi);
    if (is_root(c, n, r1)) out[k++] = r1;
    return k;
}

// Sorts a few values ascending (insertion sort, at most 6 entries).
template <typename T, typename Key>
void sort_small(T* v, int n, Key key) {
    for (int i = 1; i < n; ++i)
        for (int j = i; j > 0 && key(v[j]) < key(v[j - 1]); --j) {
            const T tmp = v[j];
            v[j] = v[j - 1];
            v[j - 1] = tmp;
        }
}

// c0 + c1 x + c2 x^2 with all |c_k| in (1e-150, 1e150) (or zero for c1): no over/underflow in
// the discriminant, so the stable formula applies directly; Newton checks each root.
int quadratic_direct(const double* c, double* roots) {
    const double a = c[2], b = c[1];
    const double ac4 = 4.0 * a * c[0];
    const double disc = discriminant(b, 0.25 * ac4);
    if (disc > 0.0) {
        const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
        double r0 = q / a, r1 = c[0] / q;
        if (r1 < r0) std::swap(r0, r1);
        const double mid = 0.5 * (r0 + r1);
        roots[0] = polish(c, 2, r0, -kInf, mid);
        roots[1] = polish(c, 2, r1, mid, kInf);
        return roots[1] > roots[0] ? 2 : 1;
    }
    if (disc >= -2.0 * kEps * (b * b + std::abs(ac4))) {
        roots[0] = -0.5 * b / a;  // double root: zero discriminant up to rounding
        return 1;
    }
    return 0;
}

int solve(const double* c, int n_in, double* roots) {
    for (int k = 0; k <= n_in; ++k)
        if (!std::isfinite(c[k])) return 0;
    int top = n_in;  // the polynomial we polish on: the full input
    while (top > 0 && c[top] == 0.0) --top;
    if (top <= 0) return 0;

    int nr = 0;
    double found[8];
    int low = 0;  // exact roots at 0 are divided out
    while (c[low] == 0.0) ++low;
    if (low > 0) found[nr++] = 0.0;
    int high = top;
    // Roots "at infinity": the largest root group is dropped when its leading coefficient is
    // negligible against the largest coefficient and the gap below it times its root count
    // reaches kDropLog2 (the dropped coefficients then move the other roots below rounding).
    double cmax = 0.0;
    for (int k = 0; k <= top; ++k) cmax = std::max(cmax, std::abs(c[k]));
    if (std::abs(c[top]) <= kEps * cmax) {
        int v[5];
        double l[5];
        const int h = newton_polygon(c, top, v, l);
        const auto slope = [&](int i) { return (l[v[i + 1]] - l[v[i]]) / (v[i + 1] - v[i]); };
        for (int i = 1; i + 1 < h; ++i) {
            if ((slope(i - 1) - slope(i)) * (v[h - 1] - v[i]) >= kDropLog2) {
                high = v[i];
                break;
            }
        }
    }
    if (high == 2 && low == 0 && std::abs(c[2]) > kEps * cmax && cmax < 1e150 &&
        std::abs(c[2]) > 1e-150 && std::abs(c[0]) > 1e-150)
        return quadratic_direct(c, roots);  // the common quadric case, no scaling needed
    Candidate cand[4];
    int nc = 0;
    if (high > low) nc = candidates(c + low, high - low, true, cand, 0);
    const int m = high - low;  // degree of what was solved
    sort_small(cand, nc, [](const Candidate& cd) { return cd.x; });

    // Candidates this close are one cluster (a near-double pair, or a triple root split by
    // rounding into a simple root and a pair): an even count is settled as a pair on p, an odd
    // count also gets a Newton run from the centre (it holds an odd number of real roots).
    double centre[4];
    int mult[4], ncl = 0;
    // (Not for a quadratic: its two roots come from an accurate discriminant.)
    for (int i = 0; i < nc; ++i) {
        const int w = cand[i].pair ? 2 : 1;
        if (ncl > 0 && m >= 3 &&
            cand[i].x - cand[i - 1].x <=
                kCloseGap * std::max(std::abs(cand[i].x), std::abs(cand[i - 1].x))) {
            const int k = mult[ncl - 1];
            centre[ncl - 1] = (centre[ncl - 1] * k + cand[i].x * w) / (k + w);
            mult[ncl - 1] += w;
            continue;
        }
        centre[ncl] = cand[i].x;
        mult[ncl++] = w;
    }

    for (int i = 0; i < ncl; ++i) {
        const double lo = i > 0 ? 0.5 * (centre[i - 1] + centre[i]) : -kInf;
        const double hi = i + 1 < ncl ? 0.5 * (centre[i] + centre[i + 1]) : kInf;
        if (mult[i] >= 2) nr += resolve_pair(c, top, centre[i], lo, hi, found + nr);
        if (mult[i] % 2 == 1) {
            const double x = polish(c, top, centre[i], lo, hi);
            if (is_root(c, top, x)) found[nr++] = x;
        }
    }
    sort_small(found, nr, [](double x) { return x; });
    int out = 0;
    for (int i = 0; i < nr; ++i) {
        if (!std::isfinite(found[i])) continue;  // beyond the range of doubles
        if (out > 0 && found[i] - roots[out - 1] <=
                           kSameRoot * std::max(std::abs(found[i]), std::abs(roots[out - 1])))
            continue;  // the same root reached twice
        if (out == n_in) break;
        roots[out++] = found[i];
    }
    return out;
}

}  // namespace

int solve_quadratic(const double c[3], double roots[2]) {
    return solve(c, 2, roots);
}
int solve_cubic(const double c[4], double roots[3]) {
    return solve(c, 3, roots);
}
int solve_quartic(const double c[5], double roots[4]) {
    return solve(c, 4, roots);
}

}  // namespace lat
