#pragma once
// Test-case generators for the quartic solver tests: random numbers, polynomials from known
// roots, rays prepared as the caller does and the coefficients of tori, spheres and
// x^4+y^4+z^4-1 along them (in double and in __float128 from the same template), and the
// per-case bookkeeping (two references, printing, assertions).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "math/vec.h"
#include "quartic_harness.h"

namespace lat::test {

class Rng {
  public:
    explicit Rng(unsigned long long seed) : g_(seed) {}
    double uni(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(g_); }
    double log_uni(double lo_exp, double hi_exp) { return std::pow(10.0, uni(lo_exp, hi_exp)); }
    double sign() { return uni(0, 1) < 0.5 ? -1.0 : 1.0; }
    Vec3 unit() {
        for (;;) {
            const Vec3 v{uni(-1, 1), uni(-1, 1), uni(-1, 1)};
            const double l = length(v);
            if (l > 0.1 && l <= 1) return v / l;
        }
    }

  private:
    std::mt19937_64 g_;
};

// Coefficients of lead * prod (x - real_i) * prod (x^2 - 2 re_j x + re_j^2 + im_j^2), in T.
template <typename T>
int poly_from_roots(T lead, const double* real, int nreal, const double* re, const double* im,
                    int npairs, T* c) {
    int n = 0;
    c[0] = lead;
    for (int k = 1; k < 5; ++k) c[k] = 0;
    const auto mul = [&](T q0, T q1, T q2, int deg) {
        for (int k = n + deg; k >= 0; --k) {
            T v = k <= n ? c[k] * q0 : T(0);
            if (k >= 1 && k - 1 <= n) v += c[k - 1] * q1;
            if (deg == 2 && k >= 2) v += c[k - 2] * q2;
            c[k] = v;
        }
        n += deg;
    };
    for (int i = 0; i < nreal; ++i) mul(-T(real[i]), T(1), T(0), 1);
    for (int j = 0; j < npairs; ++j)
        mul(T(re[j]) * T(re[j]) + T(im[j]) * T(im[j]), -2 * T(re[j]), T(1), 2);
    return n;
}

// A ray as the caller prepares it: direction normalised, origin moved to the ray point closest
// to the object's centre (the origin). Both are then exact inputs of the double and __float128
// coefficient computations.
struct PreparedRay {
    double o[3], d[3];
};
inline PreparedRay prepare(Vec3 origin, Vec3 dir) {
    const Vec3 d = normalize(dir);
    const Vec3 o = origin - d * dot(origin, d);
    return {{o.x, o.y, o.z}, {d.x, d.y, d.z}};
}

// Torus (|p|^2 + R^2 - r^2)^2 - 4 R^2 (x^2 + y^2) along o + t d.
template <typename T>
void torus_coeffs(const PreparedRay& ray, double R_, double r_, T* c) {
    const T ox = ray.o[0], oy = ray.o[1], oz = ray.o[2], dx = ray.d[0], dy = ray.d[1],
            dz = ray.d[2], R = R_, r = r_;
    const T dd = dx * dx + dy * dy + dz * dz, od = ox * dx + oy * dy + oz * dz;
    const T k = ox * ox + oy * oy + oz * oz + R * R - r * r;
    const T e = dx * dx + dy * dy, f = ox * dx + oy * dy, g = ox * ox + oy * oy;
    c[4] = dd * dd;
    c[3] = 4 * dd * od;
    c[2] = 2 * dd * k + 4 * od * od - 4 * R * R * e;
    c[1] = 4 * od * k - 8 * R * R * f;
    c[0] = k * k - 4 * R * R * g;
}

// Spheres as a quartic: (|p|^2 - a)(|p|^2 - b) along o + t d.
template <typename T>
void spheres_coeffs(const PreparedRay& ray, double a_, double b_, T* c) {
    const T ox = ray.o[0], oy = ray.o[1], oz = ray.o[2], dx = ray.d[0], dy = ray.d[1],
            dz = ray.d[2], a = a_, b = b_;
    const T dd = dx * dx + dy * dy + dz * dz, od = ox * dx + oy * dy + oz * dz,
            oo = ox * ox + oy * oy + oz * oz;
    c[4] = dd * dd;
    c[3] = 4 * dd * od;
    c[2] = 4 * od * od + 2 * dd * oo - (a + b) * dd;
    c[1] = 4 * od * oo - 2 * (a + b) * od;
    c[0] = oo * oo - (a + b) * oo + a * b;
}

// x^4 + y^4 + z^4 - 1 along o + t d.
template <typename T>
void superellipsoid_coeffs(const PreparedRay& ray, T* c) {
    for (int k = 0; k < 5; ++k) c[k] = 0;
    for (int i = 0; i < 3; ++i) {
        const T o = ray.o[i], d = ray.d[i];
        c[4] += d * d * d * d;
        c[3] += 4 * o * d * d * d;
        c[2] += 6 * o * o * d * d;
        c[1] += 4 * o * o * o * d;
        c[0] += o * o * o * o;
    }
    c[0] -= 1;
}

template <typename Coeffs>
void check_ray(const PreparedRay& ray, Coeffs coeffs, Stats& a, Stats& b) {
    double c[5];
    f128 cref[5];
    coeffs(ray, c);
    coeffs(ray, cref);
    check(c, 4, cref, a, b);
}

struct Pair {
    Stats a, b;
    explicit Pair(const char* name, double floor) {
        a.name = b.name = name;
        a.floor = b.floor = floor;
    }
    void print() const {
        a.print("A");
        b.print("B");
    }
};

inline void print_header() {
    std::printf("| %-36s | r | %5s | %5s | %4s | %4s | %4s | %4s | %7s | %7s | %7s | %5s |\n",
                "case", "polys", "roots", "miss", "spur", "pair", "lost", "max sep", "max err",
                "mean", "cond");
}

// Checks the bounds every case must meet. The bounds are the measured values (docs/solver.md)
// with a margin of about 3: no missed or spurious root, no pair lost entirely (beyond
// max_lost: clusters of 3+ roots inside their rounding radius), the largest error on roots
// separated from the others by 1% (reference A), and the largest error divided by the
// condition number against the solver's own input (reference B).
inline void expect_ok(const Pair& p, double max_sep_err, double max_cond, long max_lost = 0) {
    EXPECT_EQ(p.a.missed, 0) << p.a.name << ": " << p.a.first_bad;
    EXPECT_EQ(p.a.spurious, 0) << p.a.name << ": " << p.a.first_bad;
    EXPECT_EQ(p.b.missed, 0) << p.b.name << ": " << p.b.first_bad;
    EXPECT_EQ(p.b.spurious, 0) << p.b.name << ": " << p.b.first_bad;
    EXPECT_LE(p.a.lost, max_lost) << p.a.name << ": " << p.a.first_lost;
    EXPECT_LE(p.b.lost, max_lost) << p.b.name << ": " << p.b.first_lost;
    EXPECT_LE(p.a.max_err_sep, max_sep_err) << p.a.name << ": " << p.a.worst;
    EXPECT_LE(p.b.max_cond, max_cond) << p.b.name << ": " << p.b.worst_cond;
}

}  // namespace lat::test
