// ns per call of the closed-form polynomial solvers on realistic inputs: random rays against
// tori (and spheres for the quadratic), prepared as the caller does (direction normalised,
// origin moved to the ray point closest to the object's centre).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "geometry/quartic_solver.h"
#include "math/vec.h"

namespace {

using lat::Vec3;

struct Coeffs {
    double c[5];
};

Vec3 random_unit(std::mt19937_64& g) {
    std::uniform_real_distribution<double> u(-1, 1);
    for (;;) {
        const Vec3 v{u(g), u(g), u(g)};
        const double l = lat::length(v);
        if (l > 0.1 && l <= 1) return v / l;
    }
}

// Rays from 1.5..20 torus radii away aimed at the torus' bounding box (about 60% hit).
std::vector<Coeffs> torus_rays(int n, bool grazing) {
    std::mt19937_64 g(7);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Coeffs> out;
    for (int i = 0; i < n; ++i) {
        const double R = 1 + 4 * u(g), r = 0.1 + (0.99 * R - 0.1) * u(g);
        Vec3 o, d;
        if (grazing) {
            // Tangent to the tube at a random point, offset by up to 1e-6 r along the normal.
            const double phi = 6.3 * u(g), th = 6.3 * u(g);
            const Vec3 radial{std::cos(phi), std::sin(phi), 0};
            const Vec3 n_ = radial * std::cos(th) + Vec3{0, 0, std::sin(th)};
            Vec3 t1, t2;
            lat::orthonormal_basis(n_, t1, t2);
            d = t1;
            o = radial * R + n_ * (r * (1 + 1e-6 * (2 * u(g) - 1))) - d * (1000 * u(g));
        } else {
            o = random_unit(g) * ((1.5 + 18.5 * u(g)) * (R + r));
            const Vec3 target{(2 * u(g) - 1) * (R + r), (2 * u(g) - 1) * (R + r),
                              (2 * u(g) - 1) * r};
            d = lat::normalize(target - o);
        }
        o = o - d * lat::dot(o, d);
        const double dd = lat::dot(d, d), od = lat::dot(o, d);
        const double k = lat::dot(o, o) + R * R - r * r;
        const double e = d.x * d.x + d.y * d.y, f = o.x * d.x + o.y * d.y,
                     h = o.x * o.x + o.y * o.y;
        out.push_back({{k * k - 4 * R * R * h, 4 * od * k - 8 * R * R * f,
                        2 * dd * k + 4 * od * od - 4 * R * R * e, 4 * dd * od, dd * dd}});
    }
    return out;
}

std::vector<Coeffs> sphere_rays(int n) {
    std::mt19937_64 g(8);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Coeffs> out;
    for (int i = 0; i < n; ++i) {
        const Vec3 d = random_unit(g);
        const Vec3 o = random_unit(g) * (1.5 * u(g));  // closest point to the centre, |o| < 1.5
        const Vec3 op = o - d * lat::dot(o, d);
        out.push_back({{lat::dot(op, op) - 1, 2 * lat::dot(op, d), lat::dot(d, d), 0, 0}});
    }
    return out;
}

void run(benchmark::State& state, const std::vector<Coeffs>& in, int degree) {
    std::size_t i = 0;
    long roots = 0;
    for (auto _ : state) {
        double r[4];
        const double* c = in[i].c;
        const int n = degree == 4   ? lat::solve_quartic(c, r)
                      : degree == 3 ? lat::solve_cubic(c, r)
                                    : lat::solve_quadratic(c, r);
        roots += n;
        benchmark::DoNotOptimize(r);
        if (++i == in.size()) i = 0;
    }
    state.counters["roots/call"] =
        static_cast<double>(roots) / static_cast<double>(state.iterations());
}

void BM_QuarticTorusRays(benchmark::State& state) {
    static const auto in = torus_rays(4096, false);
    run(state, in, 4);
}
BENCHMARK(BM_QuarticTorusRays);

void BM_QuarticTorusGrazing(benchmark::State& state) {
    static const auto in = torus_rays(4096, true);
    run(state, in, 4);
}
BENCHMARK(BM_QuarticTorusGrazing);

void BM_QuadraticSphereRays(benchmark::State& state) {
    static const auto in = sphere_rays(4096);
    run(state, in, 2);
}
BENCHMARK(BM_QuadraticSphereRays);

void BM_CubicRandom(benchmark::State& state) {
    static const auto in = [] {
        std::mt19937_64 g(9);
        std::uniform_real_distribution<double> u(-10, 10);
        std::vector<Coeffs> out;
        for (int i = 0; i < 4096; ++i) out.push_back({{u(g), u(g), u(g), 1 + std::abs(u(g)), 0}});
        return out;
    }();
    run(state, in, 3);
}
BENCHMARK(BM_CubicRandom);

}  // namespace

BENCHMARK_MAIN();
