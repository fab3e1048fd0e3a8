// Accuracy of the closed-form polynomial solvers against a __float128 reference (see
// quartic_harness.h for the scoring rules and docs/solver.md for the measured table).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <type_traits>
#include <vector>

#include "geometry/quartic_solver.h"
#include "quartic_cases.h"

namespace lat::test {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- (1) polynomials from known roots ----------------------------------------------------

TEST(QuarticKnownRoots, Accuracy) {
    Rng rng(1);
    print_header();
    const int N = 1200;
    const auto run = [&](Pair& p, int nreal, auto make) {
        for (int i = 0; i < N; ++i) {
            double real[4] = {}, re[2] = {}, im[2] = {};
            make(real, re, im);
            const double lead = rng.sign() * rng.log_uni(-20, 20);
            double c[5];
            f128 cref[5];
            poly_from_roots<double>(lead, real, nreal, re, im, (4 - nreal) / 2, c);
            poly_from_roots<f128>(lead, real, nreal, re, im, (4 - nreal) / 2, cref);
            check(c, 4, cref, p.a, p.b);
        }
        p.print();
    };
    Pair sep("4 real, uniform [-10,10]", 0.0);
    run(sep, 4, [&](double* x, double*, double*) {
        for (int k = 0; k < 4; ++k) x[k] = rng.uni(-10, 10);
    });
    expect_ok(sep, 2e-11, 4);
    Pair clus("4 real, cluster gaps 1e-5..1e-2 rel", 0.0);
    run(clus, 4, [&](double* x, double*, double*) {
        const double m = rng.uni(-10, 10);
        for (int k = 0; k < 4; ++k) x[k] = m * (1 + rng.sign() * rng.log_uni(-5, -2));
    });
    expect_ok(clus, 2e-9, 32, 200);
    Pair mult("multiple roots (2,1,1 / 2,2 / 3,1)", 0.0);
    run(mult, 4, [&](double* x, double*, double*) {
        const double u = rng.uni(-10, 10), v = rng.uni(-10, 10), w = rng.uni(-10, 10);
        const int kind = static_cast<int>(rng.uni(0, 3));
        x[0] = x[1] = u;
        x[2] = kind == 2 ? u : v;
        x[3] = kind == 1 ? v : w;
    });
    expect_ok(mult, 1e-9, 8, 30);
    Pair spread("4 real, |x| in 1e-3..1e3", 0.0);
    run(spread, 4, [&](double* x, double*, double*) {
        for (int k = 0; k < 4; ++k) x[k] = rng.sign() * rng.log_uni(-3, 3);
    });
    expect_ok(spread, 5e-13, 4);
    Pair cplx("2 real + complex pair", 0.0);
    run(cplx, 2, [&](double* x, double* re, double* im) {
        x[0] = rng.uni(-10, 10);
        x[1] = rng.uni(-10, 10);
        re[0] = rng.uni(-10, 10);
        im[0] = rng.log_uni(-3, 1);
    });
    expect_ok(cplx, 1e-9, 4);
    Pair none("2 complex pairs", 0.0);
    run(none, 0, [&](double*, double* re, double* im) {
        for (int k = 0; k < 2; ++k) re[k] = rng.uni(-10, 10), im[k] = rng.log_uni(-3, 1);
    });
    expect_ok(none, 0, 4);
    Pair near("2 real + near-real pair im 1e-9..1e-4", 0.0);
    run(near, 2, [&](double* x, double* re, double* im) {
        x[0] = rng.uni(-10, 10);
        x[1] = rng.uni(-10, 10);
        re[0] = rng.uni(-10, 10);
        im[0] = std::abs(re[0]) * rng.log_uni(-9, -4);
    });
    expect_ok(near, 1e-9, 4);
}

// ---- (2) random rays against tori --------------------------------------------------------

TEST(QuarticTorus, RandomRays) {
    Rng rng(2);
    Pair p("torus, random rays", 1.0);
    for (int i = 0; i < 4000; ++i) {
        const double R = rng.uni(1, 5), r = rng.uni(0.1, 0.99 * R);
        const Vec3 origin = rng.unit() * (rng.uni(1.5, 20) * (R + r));
        const Vec3 target{rng.uni(-R - r, R + r), rng.uni(-R - r, R + r), rng.uni(-r, r)};
        check_ray(
            prepare(origin, target - origin),
            [&](const PreparedRay& ray, auto* c) { torus_coeffs(ray, R, r, c); }, p.a, p.b);
    }
    p.print();
    expect_ok(p, 3e-13, 4);
}

// ---- (3) grazing rays --------------------------------------------------------------------

TEST(QuarticGrazing, Torus) {
    Rng rng(3);
    const auto offset = [&](double scale) { return rng.sign() * scale * rng.log_uni(-15, -2); };
    Pair outer("torus outer equator, edge-on 1000R", 1.0);
    Pair inner("torus inner equator, edge-on 1000R", 1.0);
    Pair top("torus top plane z=r (2 tangencies)", 1.0);
    Pair surf("torus, tangent at random point", 1.0);
    for (int i = 0; i < 1000; ++i) {
        const double R = rng.uni(1, 5), r = rng.uni(0.1, 0.99 * R), phi = rng.uni(0, 6.3);
        const Vec3 radial{std::cos(phi), std::sin(phi), 0}, along{-std::sin(phi), std::cos(phi), 0};
        const auto torus = [&](const PreparedRay& ray, auto* c) { torus_coeffs(ray, R, r, c); };
        const double far = 1000 * R;
        check_ray(prepare(radial * (R + r + offset(r)) - along * far, along), torus, outer.a,
                  outer.b);
        check_ray(prepare(radial * (R - r + offset(r)) - along * far, along), torus, inner.a,
                  inner.b);
        const Vec3 foot = radial * rng.uni(0, R) + Vec3{0, 0, r + offset(r)};
        check_ray(prepare(foot - along * rng.uni(0, far), along), torus, top.a, top.b);
        // A point on the tube, its normal, a random tangent direction, an offset along n.
        const double th = rng.uni(0, 6.3);
        const Vec3 centre = radial * R;
        const Vec3 n = radial * std::cos(th) + Vec3{0, 0, std::sin(th)};
        const Vec3 point = centre + n * r;
        Vec3 t1, t2;
        orthonormal_basis(n, t1, t2);
        const double a = rng.uni(0, 6.3);
        const Vec3 d = t1 * std::cos(a) + t2 * std::sin(a);
        check_ray(prepare(point + n * offset(r) - d * rng.uni(0, far), d), torus, surf.a, surf.b);
    }
    for (const Pair* p : {&outer, &inner, &top, &surf}) p->print();
    expect_ok(outer, 3e-11, 4);
    expect_ok(inner, 1e-11, 4);
    expect_ok(top, 1e-11, 20);
    expect_ok(surf, 5e-11, 20);
}

TEST(QuarticGrazing, SpheresAndSuperellipsoid) {
    Rng rng(4);
    const auto offset = [&]() { return rng.sign() * rng.log_uni(-15, -2); };
    Pair two("(|p|^2-1)(|p|^2-4), tangent to either", 1.0);
    Pair one("|p|^4-1, tangent", 1.0);
    Pair sup("x^4+y^4+z^4-1, tangent", 1.0);
    for (int i = 0; i < 1000; ++i) {
        const Vec3 n = rng.unit();
        Vec3 t1, t2;
        orthonormal_basis(n, t1, t2);
        const double far = rng.uni(0, 1000);
        const double rad = rng.uni(0, 1) < 0.5 ? 1.0 : 2.0;
        check_ray(
            prepare(n * (rad + offset()) - t1 * far, t1),
            [](const PreparedRay& ray, auto* c) { spheres_coeffs(ray, 1.0, 4.0, c); }, two.a,
            two.b);
        check_ray(
            prepare(n * (1 + offset()) - t1 * far, t1),
            [](const PreparedRay& ray, auto* c) { spheres_coeffs(ray, 1.0, -1.0, c); }, one.a,
            one.b);
        // Point on x^4+y^4+z^4 = 1, its normal (x^3, y^3, z^3), a tangent direction.
        const Vec3 u = rng.unit();
        const Vec3 pt =
            u /
            std::pow(u.x * u.x * u.x * u.x + u.y * u.y * u.y * u.y + u.z * u.z * u.z * u.z, 0.25);
        const Vec3 nn = normalize(Vec3{pt.x * pt.x * pt.x, pt.y * pt.y * pt.y, pt.z * pt.z * pt.z});
        orthonormal_basis(nn, t1, t2);
        const double a = rng.uni(0, 6.3);
        const Vec3 d = t1 * std::cos(a) + t2 * std::sin(a);
        check_ray(
            prepare(pt + nn * offset() - d * far, d),
            [](const PreparedRay& ray, auto* c) { superellipsoid_coeffs(ray, c); }, sup.a, sup.b);
    }
    for (const Pair* p : {&two, &one, &sup}) p->print();
    expect_ok(two, 1e-13, 4);
    expect_ok(one, 3e-14, 4);
    expect_ok(sup, 5e-13, 4);
}

// ---- (4) degenerate leading coefficients ---------------------------------------------------

TEST(QuarticDegenerate, LeadingCoefficients) {
    Rng rng(5);
    Pair quadric("sphere |p|^2-1 as quartic (c4=c3=0)", 1.0);
    Pair cubic("cubic as quartic (c4=0)", 1.0);
    Pair tiny("cubic + c4 1e-30..1e-20 rel (dropped)", 1.0);
    Pair small("cubic + c4 1e-14..1e-3 rel (kept)", 0.0);
    Pair quad2("quadratic + c4,c3 ~1e-20 rel", 1.0);
    long far_reported = 0;
    for (int i = 0; i < 700; ++i) {
        const Vec3 n = rng.unit();
        Vec3 t1, t2;
        orthonormal_basis(n, t1, t2);
        check_ray(
            prepare(n * rng.uni(0, 1.5) - t1 * rng.uni(0, 1000), t1),
            [](const PreparedRay& ray, auto* c) {
                // The quadric |p|^2 - 1 given to the quartic solver: c4 = c3 = 0.
                using T = std::remove_reference_t<decltype(*c)>;
                const T ox = ray.o[0], oy = ray.o[1], oz = ray.o[2], dx = ray.d[0], dy = ray.d[1],
                        dz = ray.d[2];
                c[4] = c[3] = 0;
                c[2] = dx * dx + dy * dy + dz * dz;
                c[1] = 2 * (ox * dx + oy * dy + oz * dz);
                c[0] = ox * ox + oy * oy + oz * oz - 1;
            },
            quadric.a, quadric.b);
        double x[3] = {rng.uni(-10, 10), rng.uni(-10, 10), rng.uni(-10, 10)};
        const double re = rng.uni(-10, 10), im = rng.log_uni(-3, 1);
        const bool pair = rng.uni(0, 1) < 0.3;
        const double lead = rng.sign() * rng.log_uni(-5, 5);
        double c[5];
        f128 cref[5];
        poly_from_roots<double>(lead, x, pair ? 1 : 3, &re, &im, pair ? 1 : 0, c);
        poly_from_roots<f128>(lead, x, pair ? 1 : 3, &re, &im, pair ? 1 : 0, cref);
        check(c, 4, cref, cubic.a, cubic.b);
        const double big = std::fmax(std::abs(c[3]), std::fmax(std::abs(c[2]), std::abs(c[0])));
        c[4] = cref[4] = rng.sign() * big * rng.log_uni(-30, -20);
        double roots[4];
        const int nr = solve_quartic(c, roots);
        for (int k = 0; k < nr; ++k) far_reported += std::abs(roots[k]) > 1e15;
        check(c, 4, cref, tiny.a, tiny.b, 1e15);
        c[4] = cref[4] = rng.sign() * big * rng.log_uni(-14, -3);
        check(c, 4, cref, small.a, small.b);
        // A quadratic with rounding-level c3, c4.
        double q[5];
        f128 qref[5];
        poly_from_roots<double>(lead, x, 2, &re, &im, 0, q);
        poly_from_roots<f128>(lead, x, 2, &re, &im, 0, qref);
        const double qbig = std::fmax(std::abs(q[2]), std::abs(q[0]));
        q[3] = qref[3] = rng.sign() * qbig * rng.log_uni(-22, -18);
        q[4] = qref[4] = rng.sign() * qbig * rng.log_uni(-22, -18);
        check(q, 4, qref, quad2.a, quad2.b, 1e6);
    }
    for (const Pair* p : {&quadric, &cubic, &tiny, &small, &quad2}) p->print();
    expect_ok(quadric, 3e-15, 4);
    expect_ok(cubic, 5e-12, 4);
    expect_ok(tiny, 5e-12, 4);
    expect_ok(small, 3e-12, 4);
    expect_ok(quad2, 3e-13, 8);
    EXPECT_EQ(far_reported, 0);
}

// ---- (5) quadratics and cubics directly ------------------------------------------------------

TEST(QuarticLowDegree, QuadraticsAndCubics) {
    Rng rng(6);
    Pair q_real("quadratic, 2 real, scales 1e+-60", 0.0);
    Pair q_wide("quadratic, |x1/x2| 1e-15..1e-5", 0.0);
    Pair q_near("quadratic, gap 1e-12..1e-3 rel", 0.0);
    Pair q_cplx("quadratic, complex im 1e-10..1 rel", 0.0);
    Pair c_real("cubic, 3 real, scales 1e+-60", 0.0);
    Pair c_cplx("cubic, 1 real + complex pair", 0.0);
    Pair c_near("cubic, near-double gap 1e-12..1e-3", 0.0);
    Pair c_wide("cubic, |x| in 1e-4..1e4", 0.0);
    for (int i = 0; i < 1200; ++i) {
        const double s = rng.log_uni(-60, 60), lead = rng.sign() * rng.log_uni(-60, 60);
        const double u = s * rng.uni(-1, 1), v = s * rng.uni(-1, 1), w = s * rng.uni(-1, 1);
        const auto real_only = [&](Pair& p, std::initializer_list<double> xs) {
            double x[3] = {0, 0, 0}, c[5];
            f128 cref[5];
            int k = 0;
            for (double e : xs) x[k++] = e;
            const int n = poly_from_roots<double>(lead, x, k, nullptr, nullptr, 0, c);
            poly_from_roots<f128>(lead, x, k, nullptr, nullptr, 0, cref);
            check(c, n, cref, p.a, p.b);
        };
        const auto with_pair = [&](Pair& p, std::initializer_list<double> xs, double re,
                                   double im) {
            double x[3] = {0, 0, 0}, c[5];
            f128 cref[5];
            int k = 0;
            for (double e : xs) x[k++] = e;
            const int n = poly_from_roots<double>(lead, x, k, &re, &im, 1, c);
            poly_from_roots<f128>(lead, x, k, &re, &im, 1, cref);
            check(c, n, cref, p.a, p.b);
        };
        real_only(q_real, {u, v});
        real_only(q_wide, {u, u * rng.sign() * rng.log_uni(-15, -5)});
        real_only(q_near, {u, u * (1 + rng.sign() * rng.log_uni(-12, -3))});
        with_pair(q_cplx, {}, u, std::abs(u) * rng.log_uni(-10, 0));
        real_only(c_real, {u, v, w});
        with_pair(c_cplx, {u}, v, std::abs(v) * rng.log_uni(-3, 0));
        real_only(c_near, {u, v, v * (1 + rng.sign() * rng.log_uni(-12, -3))});
        real_only(c_wide, {rng.sign() * rng.log_uni(-4, 4), rng.sign() * rng.log_uni(-4, 4),
                           rng.sign() * rng.log_uni(-4, 4)});
    }
    for (const Pair* p : {&q_real, &q_wide, &q_near, &q_cplx, &c_real, &c_cplx, &c_near, &c_wide})
        p->print();
    expect_ok(q_real, 1e-13, 4);
    expect_ok(q_wide, 2e-15, 4);
    expect_ok(q_near, 0, 4);
    expect_ok(q_cplx, 0, 4);
    expect_ok(c_real, 3e-12, 4);
    expect_ok(c_cplx, 2e-11, 4);
    expect_ok(c_near, 2e-11, 20);
    expect_ok(c_wide, 1e-13, 4);
}

// ---- random coefficients of wildly different magnitudes ------------------------------------

TEST(QuarticRandom, WildCoefficients) {
    // Coefficients u * 10^(-20..20), some exactly zero: root spreads up to ~1e40, the splitting
    // path (Newton polygon + factor refinement). Against the exact roots of the input only (B);
    // polynomials where the drop rule may apply (|c_top| <= eps max|c_k|) are skipped.
    Rng rng(7);
    Stats b;
    b.name = "random coefficients 1e+-20";
    b.floor = 0.0;
    for (int i = 0; i < 20000; ++i) {
        double c[5];
        for (int k = 0; k < 5; ++k)
            c[k] = rng.uni(0, 1) < 0.05 ? 0.0 : rng.uni(-1, 1) * rng.log_uni(-20, 20);
        const int n = 2 + i % 3;
        double cmax = 0.0;
        for (int k = 0; k <= n; ++k) cmax = std::fmax(cmax, std::abs(c[k]));
        if (c[n] == 0.0 || std::abs(c[n]) <= kEps * cmax) continue;
        double roots[4];
        const int nr = run_solver(c, n, roots);
        f128 c128[5];
        for (int k = 0; k <= n; ++k) c128[k] = c[k];
        ++b.polys;
        compare(c, n, roots, nr, c128, reference_roots(c128, n), b, kInf, true);
    }
    b.print("B");
    EXPECT_EQ(b.missed, 0) << b.first_bad;
    EXPECT_EQ(b.spurious, 0) << b.first_bad;
    EXPECT_EQ(b.lost, 0) << b.first_lost;
    EXPECT_LE(b.max_cond, 4.0) << b.worst_cond;
}

// ---- edge cases ------------------------------------------------------------------------------

std::vector<double> quartic(std::initializer_list<double> coeffs) {
    double c[5] = {0, 0, 0, 0, 0}, r[4];
    int k = 0;
    for (double v : coeffs) c[k++] = v;
    const int n = solve_quartic(c, r);
    return std::vector<double>(r, r + n);
}

TEST(QuarticEdgeCases, DegenerateInputs) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    double r[4];
    const double zeros[5] = {0, 0, 0, 0, 0};
    EXPECT_EQ(solve_quadratic(zeros, r), 0);
    EXPECT_EQ(solve_cubic(zeros, r), 0);
    EXPECT_EQ(solve_quartic(zeros, r), 0);
    EXPECT_TRUE(quartic({3}).empty());                 // non-zero constant
    EXPECT_TRUE(quartic({-1, 0, 0, 0, nan}).empty());  // non-finite input
    EXPECT_TRUE(quartic({-1, kInf, 0, 0, 1}).empty());
    EXPECT_EQ(quartic({0, 0, 0, 0, 1}), std::vector<double>{0.0});  // x^4: one distinct root
    EXPECT_EQ(quartic({0, 0, 1}), std::vector<double>{0.0});
    EXPECT_EQ(quartic({2, -4}), std::vector<double>{0.5});  // linear
    EXPECT_EQ(quartic({-1, 0, 0, 0, 1}), (std::vector<double>{-1, 1}));
    EXPECT_EQ(quartic({4, 0, -5, 0, 1}), (std::vector<double>{-2, -1, 1, 2}));  // biquadratic
    EXPECT_EQ(quartic({24, -50, 35, -10, 1}), (std::vector<double>{1, 2, 3, 4}));
    EXPECT_EQ(quartic({0, -6, 11, -6, 1}), (std::vector<double>{0, 1, 2, 3}));  // exact 0
    EXPECT_EQ(quartic({1, -2, 1}), std::vector<double>{1.0});                   // double root
    EXPECT_TRUE(quartic({1, 0, 1}).empty());                                    // complex pair
    EXPECT_TRUE(quartic({1, 0, 0, 0, 1e-20}).empty());  // x^4 = -1e20: no real root
    EXPECT_EQ(quartic({-1, 0, 0, 0, 1e-20}), (std::vector<double>{-1e5, 1e5}));
    const double cubic[4] = {-6, 11, -6, 1};
    ASSERT_EQ(solve_cubic(cubic, r), 3);
    EXPECT_EQ(r[0], 1.0);
    EXPECT_EQ(r[1], 2.0);
    EXPECT_EQ(r[2], 3.0);
    // Roots beyond the range of doubles are not reported (and do not hide the others).
    EXPECT_TRUE(quartic({3.4e266, 1.6e-293}).empty());
    EXPECT_EQ(quartic({0, 0, 0, 1.77e136, 3.5e-264}), std::vector<double>{0.0});
    const double quad[3] = {-1e300, 0, 1e-300};  // x^2 = 1e600
    ASSERT_EQ(solve_quadratic(quad, r), 2);
    EXPECT_DOUBLE_EQ(r[0], -1e300);
    EXPECT_DOUBLE_EQ(r[1], 1e300);
}

TEST(QuarticEdgeCases, ScaleInvariance) {
    // Scaling the coefficients or the variable by powers of two scales the roots exactly.
    const double base[5] = {24, -50, 35, -10, 1};  // roots 1, 2, 3, 4
    for (int e : {-300, -200, -64, 0, 64, 200, 300}) {
        double c[5], r[4];
        for (int k = 0; k < 5; ++k) c[k] = std::ldexp(base[k], e);
        ASSERT_EQ(solve_quartic(c, r), 4) << e;
        for (int k = 0; k < 4; ++k) EXPECT_EQ(r[k], k + 1.0) << e;
        const int s = e / 5;  // roots 2^s (1, 2, 3, 4)
        for (int k = 0; k < 5; ++k) c[k] = std::ldexp(base[k], -s * k);
        ASSERT_EQ(solve_quartic(c, r), 4) << e;
        for (int k = 0; k < 4; ++k) EXPECT_EQ(r[k], std::ldexp(k + 1.0, s)) << e;
    }
}

TEST(QuarticEdgeCases, QuadruplesAndTriples) {
    // (x - 1)^4, (x - 1)^3 (x + 2): roots within eps^(1/m) of 1, no spurious far roots.
    for (const auto& c : {std::vector<double>{1, -4, 6, -4, 1}, {-2, 5, -3, -1, 1}}) {
        double r[4];
        const int n = solve_quartic(c.data(), r);
        ASSERT_GE(n, 1);
        int near_one = 0;
        for (int k = 0; k < n; ++k) {
            const bool one = std::abs(r[k] - 1) < 1e-3, minus_two = std::abs(r[k] + 2) < 1e-15;
            EXPECT_TRUE(one || minus_two) << r[k];
            near_one += one;
        }
        EXPECT_GE(near_one, 1);
    }
}

}  // namespace
}  // namespace lat::test
