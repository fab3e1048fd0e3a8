#pragma once
// Internals of the polynomial solver (quartic_solver.cpp): closed-form candidate roots.
// Not a public interface; declared here so the two halves can live in files of moderate size.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace lat::detail {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A candidate root from the closed forms, to be polished and verified on the input polynomial.
struct Candidate {
    double x;
    bool pair;  // centre of a near-double pair rather than a simple root
};

// floor(log2 |x|) for finite non-zero x (exact; std::logb is a library call).
inline int exponent_of(double x) {
    const int biased = static_cast<int>((std::bit_cast<std::uint64_t>(x) >> 52) & 0x7ff);
    return biased != 0 ? biased - 1023 : std::ilogb(x);  // subnormals: rare, slow path
}

// x * 2^e, exact while the result is a normal number (std::ldexp is a library call).
inline double scale2(double x, int e) {
    if (e > -1022 && e < 1023) {
        const double s = std::bit_cast<double>(static_cast<std::uint64_t>(e + 1023) << 52);
        const double r = x * s;
        if (r == 0.0 || std::abs(r) >= 0x1p-1022) return r;  // not subnormal: exact
    }
    return std::ldexp(x, e);
}

// Discriminant b^2 - 4c of y^2 + b y + c, the rounding of b^2 recovered exactly.
double discriminant(double b, double c);

// Roots of y^2 + b y + c by the stable formula; a discriminant in [-neg_tol, pos_tol] gives one
// pair centre instead. Returns the number of candidates.
int quadratic_candidates(double b, double c, double neg_tol, double pos_tol, Candidate* out);

// Upper convex hull of the points (k, log2 |c_k|) over the non-zero coefficients: its edges
// (v[i], v[i+1]) give v[i+1] - v[i] roots of magnitude about 2^-slope_i, slopes decreasing.
// Returns the number of vertices; l[k] = log2 |c_k| at the vertices' k.
int newton_polygon(const double* c, int n, int* v, double* l);

// Candidates for the roots of c[0] + ... + c[n] x^n (c[0], c[n] != 0, n <= 4): closed form,
// after splitting the polynomial into factors when its roots span many orders of magnitude.
// `exact`: the coefficients are the caller's own (not those of a computed factor).
int candidates(const double* c, int n, bool exact, Candidate* out, int depth = 0);

}  // namespace lat::detail
