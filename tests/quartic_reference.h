#pragma once
// High-precision reference for the quartic solver tests: real roots of polynomials with
// __float128 coefficients by derivative-root isolation (the real roots of p' split the line into
// intervals where p is monotone; each sign change is refined by safeguarded Newton/bisection),
// independent of the closed forms under test. Also reports near-real complex pairs (local
// extrema of p that do not reach zero) and multiple roots (critical points where p vanishes).
#include <cmath>

namespace lat::test {

__extension__ typedef __float128 f128;

inline f128 abs128(f128 x) {
    return x < 0 ? -x : x;
}
inline f128 max128(f128 a, f128 b) {
    return a > b ? a : b;
}

struct RefRoots {
    int n_real = 0;
    f128 real[4] = {};  // distinct real roots, ascending
    int mult[4] = {};   // 1, or 2+ for a multiple root (critical point where p vanishes)
    int n_near = 0;     // local extrema of p that do not reach zero: complex pairs re +- i im
    f128 near_re[3] = {};
    double near_im[3] = {};
};

inline f128 eval128(const f128* c, int n, f128 x, f128* dp = nullptr, f128* mag = nullptr) {
    f128 p = c[n], d = 0, m = abs128(c[n]);
    const f128 ax = abs128(x);
    for (int k = n - 1; k >= 0; --k) {
        d = d * x + p;
        p = p * x + c[k];
        m = m * ax + abs128(c[k]);
    }
    if (dp) *dp = d;
    if (mag) *mag = m;
    return p;
}

// Root of p in (lo, hi) where p(lo) and p(hi) have opposite signs and p is monotone.
inline f128 refine128(const f128* c, int n, f128 lo, f128 hi) {
    const bool lo_neg = eval128(c, n, lo) < 0;
    f128 x = lo / 2 + hi / 2;
    for (int it = 0; it < 400; ++it) {
        f128 d;
        const f128 p = eval128(c, n, x, &d);
        if (p == 0) return x;
        if ((p < 0) == lo_neg)
            lo = x;
        else
            hi = x;
        f128 nx = d != 0 ? x - p / d : lo / 2 + hi / 2;
        if (!(nx > lo && nx < hi)) nx = lo / 2 + hi / 2;
        if (abs128(nx - x) <= 1e-32 * abs128(nx) ||
            hi - lo <= 1e-32 * max128(abs128(lo), abs128(hi)))
            return nx;
        x = nx;
    }
    return x;
}

// Real roots of c[0] + ... + c[n] x^n (leading zeros are dropped).
inline RefRoots reference_roots(const f128* c, int n) {
    RefRoots out;
    while (n > 0 && c[n] == 0) --n;
    if (n <= 0) return out;
    if (n == 1) {
        out.real[0] = -c[0] / c[1];
        out.mult[0] = 1;
        out.n_real = 1;
        return out;
    }
    f128 dc[4];
    for (int k = 1; k <= n; ++k) dc[k - 1] = k * c[k];
    const RefRoots crit = reference_roots(dc, n - 1);
    // Fujiwara's bound 2 max |c_k / c_n|^(1/(n-k)): of the order of the largest root, so that
    // the refinement starts close (a Cauchy bound can be 1e100 times too large).
    double fb = 0;
    for (int k = 0; k < n; ++k)
        fb = std::fmax(fb, std::pow(static_cast<double>(abs128(c[k] / c[n])), 1.0 / (n - k)));
    const f128 bound = 2 * static_cast<f128>(fb) * (1 + 1e-10) + 1e-300;
    // Breakpoints: -bound, critical points, +bound. At a critical point p is "zero" when it is
    // at the level of the f128 rounding of evaluating p there.
    f128 pts[5];
    int zero[5] = {0, 0, 0, 0, 0};
    int np = 0;
    pts[np++] = -bound;
    for (int i = 0; i < crit.n_real; ++i) {
        f128 mag;
        const f128 v = eval128(c, n, crit.real[i], nullptr, &mag);
        zero[np] = abs128(v) <= 1e-30 * mag;
        pts[np++] = crit.real[i];
    }
    pts[np++] = bound;
    for (int i = 0; i < np; ++i) {
        if (i > 0) {
            const f128 a = eval128(c, n, pts[i - 1]), b = eval128(c, n, pts[i]);
            if (!zero[i - 1] && !zero[i] && ((a < 0) != (b < 0)) && out.n_real < 4) {
                out.real[out.n_real] = refine128(c, n, pts[i - 1], pts[i]);
                out.mult[out.n_real++] = 1;
            }
        }
        if (zero[i] && out.n_real < 4) {
            out.real[out.n_real] = pts[i];
            out.mult[out.n_real++] = 2;
        } else if (i > 0 && i + 1 < np) {
            // Local extremum not reaching zero: a complex pair re +- i im, im ~ sqrt(2p/p'').
            f128 d2c[3];
            for (int k = 2; k <= n; ++k) d2c[k - 2] = k * (k - 1) * c[k];
            const f128 v = eval128(c, n, pts[i]), w = eval128(d2c, n - 2, pts[i]);
            if (w != 0 && (v > 0) == (w > 0) && out.n_near < 3) {
                out.near_re[out.n_near] = pts[i];
                out.near_im[out.n_near++] = std::sqrt(static_cast<double>(2 * v / w));
            }
        }
    }
    return out;
}

}  // namespace lat::test
