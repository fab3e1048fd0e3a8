#pragma once
// Accuracy bookkeeping for the quartic solver tests: runs a solver on double coefficients and
// compares its roots with two __float128 references:
//   A: the roots of the same polynomial built in __float128 (known roots, or the ray's
//      coefficients computed in __float128): end-to-end accuracy, including the rounding of the
//      double coefficients;
//   B: the exact roots of the double coefficients given to the solver: the solver's own error,
//      measured against its condition number (eps * sum_k |c_k x^k| / |p'(x)|).
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "geometry/quartic_solver.h"
#include "quartic_reference.h"

namespace lat::test {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// A solver root within kMatch (relative) of a reference root is that root; farther from every
// reference root (and from every near-real complex pair) it is spurious. Multiple reference roots
// split by the rounding of the double coefficients by up to eps^(1/m): kMatchMultiple.
constexpr double kMatch = 1e-6;
constexpr double kMatchMultiple = 1e-4;
// Acceptable for grazing rays: two real roots closer than kPairGap (relative), or than 4 eps
// kappa (their own rounding radius: clusters of 3 or 4 roots), may be reported as one double
// root or missed; a complex pair with imaginary part below kPairGap may be reported as one
// (tangent) root. Every other real root must be found, and no other root reported.
constexpr double kPairGap = 1e-6;
// Roots farther than kSeparated (relative) from every other root, real or near-real complex,
// are "well separated".
constexpr double kSeparated = 1e-2;

struct Stats {
    std::string name;
    double floor = 1.0;  // errors are |x - x_ref| / max(|x_ref|, floor)
    long polys = 0, ref_roots = 0, found = 0, missed = 0, spurious = 0, exempt = 0, touches = 0;
    long lost = 0;  // exempt roots with no reported root near them (a pair lost, not merged)
    double max_err = 0, sum_err = 0, max_err_sep = 0;
    long n_err = 0;
    double max_cond = 0;  // max error / (eps * max(1, kappa))
    std::string worst, worst_cond, first_bad, first_lost;

    double mean_err() const { return n_err ? sum_err / static_cast<double>(n_err) : 0.0; }
    void print(const char* ref) const {
        std::printf(
            "| %-36s | %s | %5ld | %5ld | %4ld | %4ld | %4ld | %4ld | %7.1e | %7.1e | %7.1e | "
            "%5.1f |\n",
            name.c_str(), ref, polys, ref_roots, missed, spurious, exempt, lost, max_err_sep,
            max_err, mean_err(), *ref == 'B' ? max_cond : 0.0);
        if (!first_bad.empty()) std::printf("    first miss/spurious: %s\n", first_bad.c_str());
        if (!first_lost.empty()) std::printf("    first lost pair: %s\n", first_lost.c_str());
        if (!worst.empty()) std::printf("    worst error: %s\n", worst.c_str());
        if (*ref == 'B' && !worst_cond.empty())
            std::printf("    worst error / condition: %s\n", worst_cond.c_str());
    }
};

inline std::string describe(const double* c, int n, const double* roots, int nr) {
    std::string s = "c = {";
    char buf[64];
    for (int k = 0; k <= n; ++k) {
        std::snprintf(buf, sizeof buf, "%s%.17g", k ? ", " : "", c[k]);
        s += buf;
    }
    s += "} roots = {";
    for (int k = 0; k < nr; ++k) {
        std::snprintf(buf, sizeof buf, "%s%.17g", k ? ", " : "", roots[k]);
        s += buf;
    }
    return s + "}";
}

inline int run_solver(const double* c, int n, double* roots) {
    if (n == 2) return solve_quadratic(c, roots);
    if (n == 3) return solve_cubic(c, roots);
    return solve_quartic(c, roots);
}

// Rounding radius of a double root at x: p(x +- h) = 0 cannot be told from a complex pair
// x +- i h when p''(x) h^2 / 2 is within 16 eps sum |c_k x^k| (the solver's threshold is 8).
inline double double_root_radius(const f128* c, int n, double x) {
    f128 d2c[3] = {0, 0, 0}, mag;
    for (int k = 2; k <= n; ++k) d2c[k - 2] = k * (k - 1) * c[k];
    eval128(c, n, x, nullptr, &mag);
    const f128 d2 = abs128(eval128(d2c, n - 2, x));
    return d2 > 0 ? std::sqrt(static_cast<double>(32 * kEps * mag / d2)) : 1e300;
}

// Compares solver roots with reference roots (of the polynomial ref_c). Roots beyond `far`
// (absolute) are ignored on both sides: roots "at infinity" that the solver drops by design.
// `backward`: a reported root whose exact residual is within 64 eps sum |c_k x^k| is a root of
// a polynomial within rounding of ref_c, hence valid (used against the solver's own input).
inline void compare(const double* c, int n, const double* roots, int nr, const f128* ref_c,
                    const RefRoots& ref, Stats& st, double far, bool backward) {
    const auto scale = [&](double x) {
        return std::fmax(std::fmax(std::abs(x), st.floor), std::numeric_limits<double>::min());
    };
    // Pair radius at x: pairs closer than this may be reported once or missed.
    const auto pair_radius = [&](double x) {
        return std::fmax(kPairGap * scale(x), double_root_radius(ref_c, n, x));
    };
    // Relative condition number kappa = sum |c_k r^k| / (|p'(r)| scale(r)): the relative error
    // of r when the coefficients (or the evaluation of p) are perturbed by eps.
    double kappa[4], tol[4], gap[4];
    bool close[4];  // r belongs to a pair or cluster that may be reported once or missed
    for (int j = 0; j < ref.n_real; ++j) {
        f128 d, mag;
        eval128(ref_c, n, ref.real[j], &d, &mag);
        const double r = static_cast<double>(ref.real[j]);
        kappa[j] = d != 0 ? static_cast<double>(mag / abs128(d)) / scale(r) : 1e300;
        const double cluster = 4 * kEps * kappa[j] * scale(r);
        close[j] = ref.mult[j] > 1;
        gap[j] = std::numeric_limits<double>::infinity();
        for (int k = 0; k < ref.n_real; ++k) {
            if (k == j) continue;
            const double rk = static_cast<double>(ref.real[k]);
            gap[j] = std::fmin(gap[j], std::abs(rk - r));
            close[j] =
                close[j] || std::abs(rk - r) <= std::fmax(cluster, 2 * pair_radius(0.5 * (r + rk)));
        }
        for (int k = 0; k < ref.n_near; ++k) {
            const double re = static_cast<double>(ref.near_re[k]), im = ref.near_im[k];
            gap[j] = std::fmin(gap[j], std::hypot(re - r, im));
            close[j] =
                close[j] || (std::abs(re - r) <= 2 * pair_radius(re) && im <= pair_radius(re));
        }
        tol[j] = std::fmax(kMatch * scale(r), cluster);
        if (close[j]) tol[j] = std::fmax(tol[j], 2 * pair_radius(r));
        if (ref.mult[j] > 1) tol[j] = std::fmax(tol[j], kMatchMultiple * scale(r));
    }
    int n_ref = 0;
    for (int j = 0; j < ref.n_real; ++j) n_ref += abs128(ref.real[j]) <= far;
    st.ref_roots += n_ref;
    bool used[4] = {false, false, false, false}, bad = false;
    for (int i = 0; i < nr; ++i) {
        const double x = roots[i];
        if (std::abs(x) > far) continue;
        int best = -1;
        double dist = std::numeric_limits<double>::infinity();
        for (int j = 0; j < ref.n_real; ++j) {
            const double d = static_cast<double>(abs128(x - ref.real[j]));
            if (d < dist) dist = d, best = j;
        }
        if (best >= 0 && dist <= tol[best] && (!used[best] || close[best])) {
            const double r = static_cast<double>(ref.real[best]);
            if (!used[best] && ref.mult[best] == 1) {
                const double err = dist / scale(r);
                st.sum_err += err;
                ++st.n_err;
                if (err > st.max_err) {
                    st.max_err = err;
                    st.worst = describe(c, n, roots, nr);
                }
                if (gap[best] > kSeparated * scale(r))
                    st.max_err_sep = std::fmax(st.max_err_sep, err);
                const double ratio = err / (kEps * std::fmax(kappa[best], 1.0));
                if (ratio > st.max_cond) {
                    st.max_cond = ratio;
                    st.worst_cond = describe(c, n, roots, nr);
                }
            }
            used[best] = true;
            continue;
        }
        bool ok = false;
        for (int j = 0; j < ref.n_near; ++j) {
            const double re = static_cast<double>(ref.near_re[j]);
            const double rad = pair_radius(re);
            ok = ok || (std::abs(x - re) <= std::fmax(kMatch * scale(re), 2 * rad) &&
                        ref.near_im[j] <= rad);
        }
        if (backward && !ok) {
            f128 mag;
            const f128 v = eval128(ref_c, n, x, nullptr, &mag);
            ok = abs128(v) <= 64 * kEps * mag;
        }
        if (ok) {
            ++st.touches;
        } else {
            ++st.spurious;
            bad = true;
        }
    }
    for (int j = 0; j < ref.n_real; ++j) {
        if (used[j] || abs128(ref.real[j]) > far) continue;
        if (close[j]) {
            ++st.exempt;
            bool near = false;
            for (int i = 0; i < nr; ++i)
                near = near || static_cast<double>(abs128(roots[i] - ref.real[j])) <= tol[j];
            st.lost += !near;
            if (!near && st.first_lost.empty()) st.first_lost = describe(c, n, roots, nr);
        } else {
            ++st.missed;
            bad = true;
        }
    }
    if (bad && st.first_bad.empty()) st.first_bad = describe(c, n, roots, nr);
}

// Solves c (degree n) and scores it against reference A (cref) and reference B (c itself).
inline void check(const double* c, int n, const f128* cref, Stats& a, Stats& b,
                  double far = std::numeric_limits<double>::infinity()) {
    double roots[4];
    const int nr = run_solver(c, n, roots);
    f128 c128[5];
    for (int k = 0; k <= n; ++k) c128[k] = c[k];
    ++a.polys;
    ++b.polys;
    a.found += nr;
    b.found += nr;
    compare(c, n, roots, nr, cref, reference_roots(cref, n), a, far, false);
    compare(c, n, roots, nr, c128, reference_roots(c128, n), b, far, true);
}

}  // namespace lat::test
