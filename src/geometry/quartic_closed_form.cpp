// Closed-form candidate roots for the polynomial solver (see quartic_solver.cpp and
// docs/solver.md): stable quadratic formula; cubic = isolated root (trigonometric form or
// Cardano, Newton-polished) + deflated quadratic; quartic = Descartes factorisation into two
// quadratics from the largest root of the resolvent cubic; polynomials whose roots span many
// orders of magnitude are first split into factors (Newton polygon + Newton refinement).
#include "geometry/quartic_closed_form.h"

#include <algorithm>
#include <utility>

namespace lat::detail {
namespace {

// A quadratic factor (of a cubic or quartic, scaled so its roots are of order one) whose
// discriminant is within kPairDisc * (alpha^2 + 4|beta| + |alpha| + 1) of zero is a near-double
// pair, settled on the input polynomial. The "+ |alpha| + 1" is the absolute rounding of the
// factorisation (errors ~ eps in the scaled coefficients), which dominates for a pair of roots
// much smaller than the others. The settlement is exact for any gap, so erring wide is safe.
constexpr double kPairDisc = 256 * std::numeric_limits<double>::epsilon();
// Polynomials whose roots span more than 2^kSpreadLog2 in magnitude (Newton polygon) are
// first split into two factors at the widest gap: a shifted closed form rounds the small
// roots' information away (the constant term enters the depressed quartic at spread^-4).
constexpr double kSpreadLog2 = 12.0;
constexpr int kMaxNewton = 16;

// A quadratic factor y^2 + b y + c of a scaled cubic or quartic (see kPairDisc).
inline int factor_candidates(double b, double c, Candidate* out) {
    const double tol = kPairDisc * (b * b + 4.0 * std::abs(c) + std::abs(b) + 1.0);
    return quadratic_candidates(b, c, tol, tol, out);
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
        const double cos3 = std::max(-1.0, std::min(1.0, -sh / (m * m * m)));
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
    return 1 + factor_candidates(e, f, out + 1);
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
                            : std::copysign(std::sqrt(std::max(0.0, s * s - 4.0 * r)), q);
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
    int k = factor_candidates(al1, be1, out);
    k += factor_candidates(al2, be2, out + k);
    return k;
}

// Closed-form candidates for the roots of c[0] + ... + c[m] x^m (c[0], c[m] != 0), scaled so
// its root radius is near one. `exact`: the coefficients are the caller's (not a factor's).
int closed_form(const double* c, int m, bool exact, Candidate* out) {
    // x = 2^e y with 2^e near the root radius; a[k] = c_k 2^(e k) / (c_m 2^(e m)).
    static constexpr double kInv[5] = {0.0, 1.0, 0.5, 1.0 / 3.0, 0.25};
    double log_r = -kInf;
    const int lm = exponent_of(c[m]);
    for (int k = 0; k < m; ++k)
        if (c[k] != 0.0) log_r = std::max(log_r, (exponent_of(c[k]) - lm) * kInv[m - k]);
    const int e = static_cast<int>(std::floor(log_r + 0.5));
    const int g = lm + e * m;
    double a[5] = {0, 0, 0, 0, 0};
    for (int k = 0; k <= m; ++k) a[k] = scale2(c[k], e * k - g);
    const double inv = 1.0 / a[m];  // one division; the extra rounding is polished away
    for (int k = 0; k < m; ++k) a[k] *= inv;
    int ny = 0;
    if (m == 1) {
        out[ny++] = {-a[0], false};
    } else if (m == 2 && exact) {
        // Exact coefficients: two roots whenever D > 0; a double root when D is zero up to the
        // rounding of the scaled coefficients.
        ny = quadratic_candidates(a[1], a[0], 2.0 * kEps * (a[1] * a[1] + 4.0 * std::abs(a[0])),
                                  0.0, out);
    } else if (m == 2) {
        ny = factor_candidates(a[1], a[0], out);
    } else if (m == 3) {
        ny = cubic_candidates(a[2], a[1], a[0], out);
    } else {
        ny = quartic_candidates(a[3], a[2], a[1], a[0], out);
    }
    for (int k = 0; k < ny; ++k) out[k].x = scale2(out[k].x, e);
    return ny;
}

// Solves m x = b in place (size n <= 5) by Gaussian elimination with partial pivoting.
bool solve_linear(double m[5][5], double* b, int n) {
    for (int col = 0; col < n; ++col) {
        int piv = col;
        for (int r = col + 1; r < n; ++r)
            if (std::abs(m[r][col]) > std::abs(m[piv][col])) piv = r;
        if (m[piv][col] == 0.0) return false;
        for (int k = 0; k < n; ++k) std::swap(m[col][k], m[piv][k]);
        std::swap(b[col], b[piv]);
        for (int r = col + 1; r < n; ++r) {
            const double f = m[r][col] / m[col][col];
            for (int k = col; k < n; ++k) m[r][k] -= f * m[col][k];
            b[r] -= f * b[col];
        }
    }
    for (int r = n - 1; r >= 0; --r) {
        for (int k = r + 1; k < n; ++k) b[r] -= m[r][k] * b[k];
        b[r] /= m[r][r];
    }
    return true;
}

// Refines p = f q (p of degree n, f monic of degree k holding the k smallest roots, q of degree
// n - k) by Newton's method on the n + 1 coefficient equations, starting from the two Newton
// polygon groups. Well conditioned when the groups are far apart (their resultant is large).
// p is scaled so the gap between the groups is around |x| = 1.
bool split_factor(const double* p, int n, int k, double* f, double* q) {
    for (int i = 0; i < k; ++i) f[i] = p[i] / p[k];
    f[k] = 1.0;
    for (int l = 0; l <= n - k; ++l) q[l] = p[k + l];
    double scale = 0.0;
    for (int j = 0; j <= n; ++j) scale = std::max(scale, std::abs(p[j]));
    double best = kInf, bf[5], bq[5];
    for (int it = 0; it < 12; ++it) {
        double r[5], res = 0.0;
        for (int j = 0; j <= n; ++j) {
            double fq = 0.0;
            for (int i = 0; i <= k; ++i)
                if (j - i >= 0 && j - i <= n - k) fq += f[i] * q[j - i];
            r[j] = p[j] - fq;
            res = std::max(res, std::abs(r[j]));
        }
        if (!(res < best)) break;  // stopped improving: keep the best iterate
        best = res;
        for (int i = 0; i <= k; ++i) bf[i] = f[i];
        for (int l = 0; l <= n - k; ++l) bq[l] = q[l];
        if (res <= kEps * scale) break;
        double m[5][5] = {};
        for (int j = 0; j <= n; ++j) {
            for (int i = 0; i < k; ++i)
                if (j - i >= 0 && j - i <= n - k) m[j][i] = q[j - i];
            for (int l = 0; l <= n - k; ++l)
                if (j - l >= 0 && j - l <= k) m[j][k + l] = f[j - l];
        }
        if (!solve_linear(m, r, n + 1)) break;
        for (int i = 0; i < k; ++i) f[i] += r[i];
        for (int l = 0; l <= n - k; ++l) q[l] += r[k + l];
    }
    for (int i = 0; i <= k; ++i) f[i] = bf[i];
    for (int l = 0; l <= n - k; ++l) q[l] = bq[l];
    return best <= 64.0 * kEps * scale && f[0] != 0.0 && q[0] != 0.0 && q[n - k] != 0.0;
}

}  // namespace

// Discriminant b^2 - 4c with the rounding error of b^2 recovered exactly (Dekker's product;
// std::fma is a slow library call on targets without an FMA instruction).
double discriminant(double b, double c) {
    constexpr double kSplit = 134217729.0;  // 2^27 + 1
    const double bb = b * b;
    if (!(std::abs(b) < 1e150)) return bb - 4.0 * c;  // splitting would overflow
    const double t = kSplit * b, hi = t - (t - b), lo = b - hi;
    const double err = ((hi * hi - bb) + 2.0 * hi * lo) + lo * lo;
    return (bb - 4.0 * c) + err;
}

// Roots of y^2 + b y + c: stable formula (no cancellation: q = -(b + sign(b) sqrt(D)) / 2,
// roots q and c / q). A discriminant in [-neg_tol, pos_tol] makes a pair centre.
int quadratic_candidates(double b, double c, double neg_tol, double pos_tol, Candidate* out) {
    const double disc = discriminant(b, c);
    if (disc > pos_tol) {
        const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
        out[0] = {q, false};
        out[1] = {q != 0.0 ? c / q : 0.0, false};
        return 2;
    }
    if (disc >= -neg_tol) {
        out[0] = {-0.5 * b, true};
        return 1;
    }
    return 0;
}

// Upper convex hull of the points (k, log2 |c_k|) over the non-zero coefficients: its edges
// (v[i], v[i+1]) give v[i+1] - v[i] roots of magnitude about 2^-slope_i, slopes decreasing.
int newton_polygon(const double* c, int n, int* v, double* l) {
    int h = 0;
    for (int k = 0; k <= n; ++k) {
        if (c[k] == 0.0) continue;
        l[k] = static_cast<double>(exponent_of(c[k]));
        // Pop the last vertex while it lies on or below the chord from the one before to k.
        while (h >= 2 && (l[v[h - 1]] - l[v[h - 2]]) * (k - v[h - 2]) <=
                             (l[k] - l[v[h - 2]]) * (v[h - 1] - v[h - 2]))
            --h;
        v[h++] = k;
    }
    return h;
}

// Candidates for the roots of c[0] + ... + c[n] x^n (c[0], c[n] != 0): closed form, after
// splitting the polynomial into factors when its roots span many orders of magnitude.
int candidates(const double* c, int n, bool exact, Candidate* out, int depth) {
    if (n <= 2) return closed_form(c, n, exact, out);  // the stable formula has no spread limit
    int v[5];
    double l[5];
    const int h = newton_polygon(c, n, v, l);
    const auto slope = [&](int i) { return (l[v[i + 1]] - l[v[i]]) / (v[i + 1] - v[i]); };
    if (h >= 3 && depth < 3 && slope(0) - slope(h - 2) >= kSpreadLog2) {
        int best = 1;  // vertex at the widest gap between consecutive magnitude groups
        for (int i = 2; i + 1 < h; ++i)
            if (slope(i - 1) - slope(i) > slope(best - 1) - slope(best)) best = i;
        const int k = v[best];
        // Scale x = 2^e y with 2^e in the middle of the gap, and normalise the coefficients.
        const int e = static_cast<int>(std::floor(0.5 - 0.5 * (slope(best - 1) + slope(best))));
        double a[5] = {0, 0, 0, 0, 0}, f[5] = {0, 0, 0, 0, 0}, q[5] = {0, 0, 0, 0, 0};
        int g = -100000;
        for (int j = 0; j <= n; ++j)
            if (c[j] != 0.0) g = std::max(g, static_cast<int>(l[j]) + e * j);
        for (int j = 0; j <= n; ++j) a[j] = scale2(c[j], e * j - g);
        if (split_factor(a, n, k, f, q)) {
            int nf = candidates(f, k, false, out, depth + 1);
            nf += candidates(q, n - k, false, out + nf, depth + 1);
            for (int i = 0; i < nf; ++i) out[i].x = scale2(out[i].x, e);
            return nf;
        }
    }
    return closed_form(c, n, exact, out);
}

}  // namespace lat::detail
