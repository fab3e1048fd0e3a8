#pragma once
// Trivariate polynomials of total degree <= 4 (paper eq. 3): f(x,y,z) = sum a_ijk x^i y^j z^k.
// By convention f < 0 inside the solid and f > 0 outside.
#include <array>
#include <string>

#include "math/vec.h"

namespace lat {

struct Poly3 {
    static constexpr int kMaxDegree = 4;
    static constexpr int kTerms = 35;  // monomials with i + j + k <= 4

    std::array<double, kTerms> a{};

    // Dense index of monomial x^i y^j z^k (requires i + j + k <= 4).
    static int index(int i, int j, int k);
    // The exponents of dense index n.
    static std::array<int, 3> exponents(int n);

    double& at(int i, int j, int k) { return a[static_cast<std::size_t>(index(i, j, k))]; }
    double at(int i, int j, int k) const { return a[static_cast<std::size_t>(index(i, j, k))]; }

    // Highest total degree with a non-zero coefficient (0 for a constant, -1 for zero).
    int degree() const;
    double eval(Vec3 p) const;
    Vec3 gradient(Vec3 p) const;
    // c[0..4] with f(o + t d) = c[0] + c[1] t + ... + c[4] t^4.
    void along_ray(Vec3 o, Vec3 d, double c[5]) const;

    // Readable form, e.g. "x^2 + y^2 + z^2 - 1".
    std::string to_string() const;
};

Poly3 operator+(const Poly3& f, const Poly3& g);
Poly3 operator*(double s, const Poly3& f);

}  // namespace lat
