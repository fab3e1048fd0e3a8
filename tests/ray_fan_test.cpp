// Two rays from one origin against a sphere or a flat-ended cylinder at once (geometry/ray_fan.h):
// each lane must answer as the scalar intersect() does, bit for bit, on random rays and on the
// awkward ones (grazing, along and across the axis, through the rims, from the surface, zero).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "geometry/capped_cylinder.h"
#include "geometry/ray_fan.h"
#include "geometry/sphere.h"

namespace lat {
namespace {

template <class S>
void expect_lanes_as_scalar(const S& shape, const Vec3& o, const Vec3& d0, const Vec3& d1, double tmax0,
                            double tmax1) {
    RayFan f;
    f.o = o;
    f.d = {_mm_set_pd(d1.x, d0.x), _mm_set_pd(d1.y, d0.y), _mm_set_pd(d1.z, d0.z)};
    f.tmin = _mm_setzero_pd();
    f.tmax = _mm_set_pd(tmax1, tmax0);
    FanHits out;
    const unsigned m = shape.intersect_fan(f, out);
    alignas(16) double t[2], part[2];
    _mm_store_pd(t, out.t);
    _mm_store_pd(part, out.part);
    const Vec3 d[2] = {d0, d1};
    const double tmax[2] = {tmax0, tmax1};
    for (int j = 0; j < 2; ++j) {
        Crossing c;
        const bool hit = shape.intersect({o, d[j]}, 0.0, tmax[j], c);
        ASSERT_EQ(hit, (m >> j & 1) != 0) << "lane " << j << " d " << d[j].x << " " << d[j].y << " " << d[j].z;
        if (!hit) continue;
        EXPECT_EQ(std::memcmp(&c.t, &t[j], sizeof(double)), 0) << c.t << " vs " << t[j];
        EXPECT_EQ(c.part, static_cast<std::uint32_t>(part[j]));
    }
}

template <class S>
void check_shape(const S& shape, const std::vector<Vec3>& origins, const std::vector<Vec3>& special) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-3, 3), tm(0.2, 2);
    std::vector<Vec3> dirs = special;
    for (int i = 0; i < 400; ++i) dirs.push_back({u(rng), u(rng), u(rng)});
    for (const Vec3& o : origins)
        for (std::size_t i = 0; i < dirs.size(); ++i) {
            const Vec3 a = dirs[i] - o, b = dirs[(i * 7 + 3) % dirs.size()] - o;  // towards targets
            expect_lanes_as_scalar(shape, o, a, b, 1.0 + 1e-12, tm(rng));
            expect_lanes_as_scalar(shape, o, dirs[i], a, tm(rng), 1.0 + 1e-12);
        }
}

TEST(RayFan, SphereLanesAnswerAsTheScalarTest) {
    const SphereShape s({0.5, 0.25, 0}, 1.0);
    // Targets on and tangent to the sphere, through its centre, and the origin itself (zero).
    const std::vector<Vec3> special = {{1.5, 0.25, 0}, {0.5, 1.25, 0},   {0.5, 0.25, 1}, {0.5, 0.25, 0},
                                       {1.5, 3, 0},    {-0.5, -3, 0},    {3, 0.25, 1}};
    check_shape(s, {{-2, 0.25, 0}, {1.5, 0.25, 0}, {0.5, 0.25, 0}, {0.5, 2, 1}, {-2, 1.25, 0}}, special);
    const std::vector<Vec3> zero = {{-2, 0.25, 0}};
    expect_lanes_as_scalar(s, zero[0], {0, 0, 0}, {1, 0, 0}, 2.0, 5.0);
}

TEST(RayFan, CylinderLanesAnswerAsTheScalarTest) {
    const CappedCylinderShape c({0, 0, 0}, {0, 0, 2}, 0.5);
    // Targets on the rims, the axis, the caps, the side, and across the axis (da = 0).
    const std::vector<Vec3> special = {{0.5, 0, 0},  {0.5, 0, 2}, {0, 0, 1},   {0, 0, 3},  {0.5, 0, 1},
                                       {-0.5, 0, 2}, {0, 0.5, 0}, {2, 0, 0.5}, {2, 0.5, 1}, {0, 0, -1}};
    check_shape(c, {{-2, 0, 1}, {0, 0, -1}, {0.5, 0, 1}, {0, 0, 1}, {-2, 0.5, 2}, {0.5, 0, 3}, {1, 1, 0}}, special);
    expect_lanes_as_scalar(c, {-2, 0, 1}, {0, 0, 0}, {1, 0, 0}, 2.0, 5.0);
    // Along the axis (no slant) and across it (parallel to the caps).
    expect_lanes_as_scalar(c, {0.25, 0, -1}, {0, 0, 1}, {0, 0, 4}, 5.0, 5.0);
    expect_lanes_as_scalar(c, {0.75, 0, -1}, {0, 0, 1}, {1, 0, 0}, 5.0, 5.0);
    expect_lanes_as_scalar(c, {-2, 0, 2}, {1, 0, 0}, {4, 0, 0}, 5.0, 5.0);
    expect_lanes_as_scalar(c, {-2, 0, 3}, {1, 0, 0}, {4, 0.5, 0}, 5.0, 5.0);
}

}  // namespace
}  // namespace lat
