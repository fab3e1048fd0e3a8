// Closed-form real roots of polynomials of degree <= 4, made robust (see docs/solver.md).
//
// Pipeline shared by the three entry points:
//   1. reject non-finite input; drop negligible leading coefficients (roots "at infinity");
//      an exactly zero constant term gives the exact root 0 and is divided out;
//   2. scale x = 2^e y (exact) so the monic polynomial in y has coefficients of order one;
//   3. closed form in y: stable quadratic formula; cubic = isolated root (trigonometric or
//      Cardano) + deflated quadratic; quartic = Descartes factorisation into two quadratics
//      from the largest root of the resolvent cubic;
//   4. each quadratic factor yields two simple candidates, nothing (complex pair), or, when its
//      discriminant is zero up to the factorisation's rounding, a "pair centre" that is settled
//      on the input polynomial itself (critical point of p, sign of p there);
//   5. Newton polishing on the input polynomial inside each candidate's cell, verification of
//      the residual, sorting and removal of duplicates.
#include "geometry/quartic_solver.h"

#include <cmath>
#include <limits>

namespace lat {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();

// |p(x)| <= kResidual * eps * sum_k |c_k x^k| means p(x) = 0 up to the rounding of evaluating
// p at x (Horner for degree 4 is within about 8 eps * sum, half an ulp of x adds <= 2 eps * sum).
constexpr double kResidual = 32.0;
// A leading coefficient is dropped when the roots it adds lie beyond 2^kFarLog2 (~1.3e8) times
// the root radius of the remaining polynomial: they are "at infinity" for the caller, and the
// remaining roots move by less than 2^-kFarLog2 relative before being polished on the full input.
constexpr double kFarLog2 = 27.0;
// Quadratic factors of the cubic/quartic whose discriminant is within kPairDisc of its terms
// (alpha^2 + 4|beta|) are near-double pairs, settled on the input polynomial: the discriminant's
// own rounding is far below, and pairs that wide (gap ~ 2e-6 relative) are still far closer
// than any other root in practice.
constexpr double kPairDisc = 1e-12;
// A critical point where |p| <= kDouble * eps * sum |c_k x^k| is a double root: the rounding
// of p there is within that. Pairs further apart are split (see resolve_pair).
constexpr double kDouble = 8.0;
// Candidates closer than this (relative) form one cluster (near-double pair or triple root).
constexpr double kCloseGap = 1e-6;
// Polished roots closer than this (relative) are the same root found twice.
constexpr double kSameRoot = 1e-13;
constexpr int kMaxNewton = 16;

struct Candidate {
    double x;
    bool pair;  // centre of a near-double pair rather than a simple root
};

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
    if (!(p * ddp < 0.0)) return 0;
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

// Discriminant b^2 - 4c with the rounding error of b^2 recovered by an FMA.
inline double discriminant(double b, double c) {
    const double bb = b * b;
    return (bb - 4.0 * c) + std::fma(b, b, -bb);
}

// Roots of y^2 + b y + c: stable formula (no cancellation: q = -(b + sign(b) sqrt(D)) / 2,
// roots q and c / q). A discriminant within tol of zero makes a pair centre.
int quadratic_candidates(double b, double c, double tol, Candidate* out) {
    const double disc = discriminant(b, c);
    const double terms = b * b + 4.0 * std::abs(c);
    if (disc > tol * terms) {
        const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
        out[0] = {q, false};
        out[1] = {q != 0.0 ? c / q : 0.0, false};
        return 2;
    }
    if (disc >= -tol * terms) {
        out[0] = {-0.5 * b, true};
        return 1;
    }
    return 0;
}

// Newton on the monic cubic y^3 + a y^2 + b y + c; stops when the step stops shrinking.
double polish_cubic(double a, double b, double c, double y) {
    double prev = kInf;
    for (int it = 0; it < kMaxNewton; ++it) {
        const double f = ((y + a) * y + b) * y + c;
        const double df = (3.0 * y + 2.0 * a) * y + b;
        if (f == 0.0 || df == 0.0) break;
        const double step = f / df;
        if (!(std::abs(step) < prev)) break;
        const double ny = y - step;
        if (ny == y) break;
        y = ny;
        prev = std::abs(step);
    }
    return y;
}

// One real root of the monic cubic y^3 + a y^2 + b y + c (coefficients of order one): the
// largest if `largest`, otherwise the one farthest from the other two (so that deflating it
// leaves the close pair, if any, in the quadratic). Closed form, then Newton-polished.
double cubic_root(double a, double b, double c, bool largest) {
    // Depressed cubic z^3 + P z + Q with y = z + t (Taylor shift by Horner).
    const double t = -a / 3.0;
    double e1 = a + t;
    double e2 = b + t * e1;
    const double Q = c + t * e2;
    e1 += t;
    const double P = e2 + t * e1;
    const double h = 0.5 * Q, g = P / 3.0;
    const double disc = h * h + g * g * g;
    double z;
    if (disc < 0.0) {
        // Three real roots: trigonometric form; 2m cos(theta) is the largest, and it is also
        // the farthest from the others when h <= 0 (otherwise take the mirrored smallest).
        const double m = std::sqrt(-g);
        const double sh = largest ? h : -std::abs(h);
        const double cos3 = std::fmax(-1.0, std::fmin(1.0, -sh / (m * m * m)));
        z = 2.0 * m * std::cos(std::acos(cos3) / 3.0);
        if (!largest && h > 0.0) z = -z;
    } else {
        // One real root (or a double one): Cardano without cancellation.
        const double A = -std::copysign(std::cbrt(std::abs(h) + std::sqrt(disc)), h);
        z = A != 0.0 ? A - g / A : 0.0;
    }
    return polish_cubic(a, b, c, z + t);
}

// Candidates of the monic cubic y^3 + a y^2 + b y + c.
int cubic_candidates(double a, double b, double c, Candidate* out) {
    const double y0 = cubic_root(a, b, c, false);
    // Deflate: (y - y0)(y^2 + e y + f). f = -c / y0 keeps its relative accuracy.
    const double e = a + y0;
    const double f = y0 != 0.0 ? -c / y0 : b + e * y0;
    out[0] = {y0, false};
    return 1 + quadratic_candidates(e, f, kPairDisc, out + 1);
}

// Candidates of the monic quartic y^4 + a y^3 + b y^2 + c y + d (coefficients of order one).
int quartic_candidates(double a, double b, double c, double d, Candidate* out) {
    // Depressed quartic z^4 + p z^2 + q z + r with y = z + y0, y0 = -a/4 (Taylor shift).
    const double y0 = -0.25 * a;
    double e1 = a + y0;
    double e2 = b + y0 * e1;
    double e3 = c + y0 * e2;
    const double r = d + y0 * e3;
    e1 += y0;
    e2 += y0 * e1;
    const double q = e3 + y0 * e2;
    e1 += y0;
    const double p = e2 + y0 * e1;

    // Descartes: z^4 + p z^2 + q z + r = (z^2 + u z + v)(z^2 - u z + w) with U = u^2 the largest
    // root of U^3 + 2p U^2 + (p^2 - 4r) U - q^2 (it is >= 0: the cubic is -q^2 <= 0 at U = 0).
    double U = cubic_root(2.0 * p, p * p - 4.0 * r, -q * q, true);
    if (!(U > 0.0)) U = 0.0;
    const double u = std::sqrt(U);
    // v + w = p + U and w - v = q / u, or equally (w - v)^2 = (p + U)^2 - 4r. The first has
    // error ~ |w - v| eps / |q|, the second ~ eps (s^2 + 4|r|) / |w - v|: take the smaller.
    // Small q (rounding level) is common: a ray from near the centre of a symmetric surface.
    const double s = p + U;
    const double terms = s * s + 4.0 * std::abs(r);
    const double diff = std::abs(q) < U * terms
                            ? q / u
                            : std::copysign(std::sqrt(std::fmax(0.0, s * s - 4.0 * r)), q);
    double v = 0.5 * (s - diff), w = 0.5 * (s + diff);
    // v w = r: compute the smaller from the larger (cancellation-free).
    if (std::abs(v) > std::abs(w)) {
        if (v != 0.0) w = r / v;
    } else if (w != 0.0) {
        v = r / w;
    }
    // Back to y: factors y^2 + al1 y + be1 and y^2 + al2 y + be2 with be1 be2 = d, al1 + al2 = a.
    const double al1 = u - 2.0 * y0, al2 = -u - 2.0 * y0;
    double be1 = v + y0 * (y0 - u), be2 = w + y0 * (y0 + u);
    if (std::abs(be1) > std::abs(be2)) {
        if (be1 != 0.0) be2 = d / be1;
    } else if (be2 != 0.0) {
        be1 = d / be2;
    }
    int k = quadratic_candidates(al1, be1, kPairDisc, out);
    k += quadratic_candidates(al2, be2, kPairDisc, out + k);
    return k;
}

// Degree after dropping leading coefficients that are zero or negligible (see kFarLog2).
int effective_degree(const double* c, int n) {
    while (n > 0) {
        if (c[n] == 0.0) {
            --n;
            continue;
        }
        int m = n - 1;
        while (m >= 0 && c[m] == 0.0) --m;
        if (m <= 0) return n;  // c_n x^n (+ c_0): nothing to compare the roots with
        // log2 of the root radius of c_0 + ... + c_m x^m, and of the roots c_n adds.
        double log_r = -kInf;
        const double lm = std::logb(std::abs(c[m]));
        for (int k = 0; k < m; ++k)
            if (c[k] != 0.0) log_r = std::fmax(log_r, (std::logb(std::abs(c[k])) - lm) / (m - k));
        if (log_r == -kInf) return n;  // c_n x^n + c_m x^m: same
        const double log_far = (lm - std::logb(std::abs(c[n]))) / (n - m);
        if (log_far - log_r < kFarLog2) return n;
        n = m;
    }
    return n;
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

int solve(const double* c, int n_in, double* roots) {
    for (int k = 0; k <= n_in; ++k)
        if (!std::isfinite(c[k])) return 0;
    int top = n_in;  // the polynomial we polish on: the full input
    while (top > 0 && c[top] == 0.0) --top;
    const int n = effective_degree(c, n_in);
    if (n <= 0) return 0;

    int nr = 0;
    double found[8];
    int z = 0;  // exact roots at 0, divided out
    while (c[z] == 0.0) ++z;
    if (z > 0) found[nr++] = 0.0;
    Candidate cand[4];
    int nc = 0;
    const int m = n - z;
    const double* cz = c + z;
    if (m >= 1) {
        // x = 2^e y with 2^e near the root radius; a[k] = c_k 2^(e k) / (c_m 2^(e m)).
        double log_r = -kInf;
        const double lm = std::logb(std::abs(cz[m]));
        for (int k = 0; k < m; ++k)
            if (cz[k] != 0.0) log_r = std::fmax(log_r, (std::logb(std::abs(cz[k])) - lm) / (m - k));
        const int e = static_cast<int>(std::lround(log_r));
        const int g = static_cast<int>(lm) + e * m;
        double a[5];
        for (int k = 0; k <= m; ++k) a[k] = std::ldexp(cz[k], e * k - g);
        for (int k = 0; k < m; ++k) a[k] /= a[m];
        Candidate y[4];
        int ny = 0;
        if (m == 1) {
            y[ny++] = {-a[0], false};
        } else if (m == 2) {
            ny = quadratic_candidates(a[1], a[0], 2.0 * kEps, y);
        } else if (m == 3) {
            ny = cubic_candidates(a[2], a[1], a[0], y);
        } else {
            ny = quartic_candidates(a[3], a[2], a[1], a[0], y);
        }
        for (int k = 0; k < ny; ++k) cand[nc++] = {std::ldexp(y[k].x, e), y[k].pair};
    }
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
                kCloseGap * std::fmax(std::abs(cand[i].x), std::abs(cand[i - 1].x))) {
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
    sort_small(found, nr, [](double v) { return v; });
    int out = 0;
    for (int i = 0; i < nr; ++i) {
        if (out > 0 && found[i] - roots[out - 1] <=
                           kSameRoot * std::fmax(std::abs(found[i]), std::abs(roots[out - 1])))
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
