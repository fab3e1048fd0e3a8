// Table 1: the sphere and cylinder rows reproduce the paper's printed values; N_lp by
// enumeration equals eq. (2) everywhere; the hook row equals an independent brute-force count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene/table1_file.h"
#include "test_paths.h"

namespace lat {
namespace {

TEST(Table1, PaperNotation) {
    EXPECT_EQ(paper_notation(2430), "2.4 (3)");
    EXPECT_EQ(paper_notation(5368334), "5.4 (6)");
    EXPECT_EQ(paper_notation(510), "5.1 (2)");
    EXPECT_TRUE(matches_printed(9950, 9900));  // the paper truncates this one
    EXPECT_TRUE(matches_printed(518912, 520000));
    EXPECT_FALSE(matches_printed(87574, 94000));
}

TEST(Table1, SphereAndCylinderRowsMatchThePaper) {
    const auto rows = compute_table1(test::source_path("examples/table1.json"), false);
    ASSERT_EQ(rows.size(), 5u);
    for (const Table1Row& r : rows) {
        for (const Table1Cell& c : r.cells) {
            EXPECT_EQ(c.n_lp_eq2, c.n_lp_enumerated) << r.primitive << " " << c.sigma_inv;
            const bool paper_row = r.primitive.find("sphere") == 0 || r.primitive.find("cylinder") == 0;
            if (!paper_row) continue;
            EXPECT_TRUE(c.n_lp_matches) << r.primitive << " " << c.sigma_inv;
            EXPECT_TRUE(c.n_ix_matches) << r.primitive << " " << c.sigma_inv << ": " << c.n_ix;
            EXPECT_TRUE(c.ratio_matches) << r.primitive << " " << c.sigma_inv << ": " << c.ratio;
        }
    }
    // The exact counts behind the printed ones (closed solids, the file's boxes).
    EXPECT_EQ(rows[0].cells[0].n_ix, 510u);
    EXPECT_EQ(rows[1].cells[1].n_ix, 93614u);
    EXPECT_EQ(rows[2].cells[1].n_ix, 5368334u);
}

// Independent count: distance from each segment to the hook's capsules (the hook's cylinders
// join spheres of their own radius, so the solid is a union of capsules), closed solid.
double segment_distance(const double p0[3], const double p1[3], const double q0[3], const double q1[3]) {
    double d1[3], d2[3], r[3];
    for (int i = 0; i < 3; ++i) d1[i] = p1[i] - p0[i], d2[i] = q1[i] - q0[i], r[i] = p0[i] - q0[i];
    auto dot = [](const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r), c = dot(d1, r), b = dot(d1, d2);
    double s = 0, t = 0;
    if (a <= 1e-30) {
        t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double den = a * e - b * b;
        s = den != 0 ? std::clamp((b * f - c * e) / den, 0.0, 1.0) : 0.0;
        t = (b * s + f) / e;
        if (t < 0) t = 0, s = std::clamp(-c / a, 0.0, 1.0);
        else if (t > 1) t = 1, s = std::clamp((b - c) / a, 0.0, 1.0);
    }
    double d = 0;
    for (int i = 0; i < 3; ++i) {
        const double x = p0[i] + s * d1[i] - q0[i] - t * d2[i];
        d += x * x;
    }
    return std::sqrt(d);
}

std::uint64_t brute_force_hook(int k) {
    const int n[3] = {4 * k, 2 * k, 4 * k};
    const double h = 1.0 / k;
    const double centres[4][3] = {{1, 1, 1}, {1, 1, 3}, {3, 1, 3}, {3, 1, 2}};
    std::vector<std::pair<std::array<double, 3>, int>> points;  // face points, face by face
    for (int f = 0; f < 6; ++f) {
        const int a = f / 2, ua = (a + 1) % 3, va = (a + 2) % 3;
        for (int u = 0; u <= n[ua]; ++u)
            for (int v = 0; v <= n[va]; ++v) {
                std::array<double, 3> c{};
                c[static_cast<std::size_t>(a)] = (f & 1) ? n[a] * h : 0.0;
                c[static_cast<std::size_t>(ua)] = u * h;
                c[static_cast<std::size_t>(va)] = v * h;
                points.push_back({c, f});
            }
    }
    std::uint64_t hits = 0;
    for (const auto& [p, fp] : points)
        for (const auto& [q, fq] : points) {
            if (fp == fq) continue;
            double d = 1e9;
            for (int i = 0; i < 3; ++i) d = std::min(d, segment_distance(p.data(), q.data(), centres[i], centres[i + 1]));
            if (d <= 0.5 + 1e-9) ++hits;
        }
    return hits;
}

TEST(Table1, HookRowMatchesAnIndependentCount) {
    const auto rows = compute_table1(test::source_path("examples/table1.json"), false);
    const Table1Row& hook = rows[3];
    ASSERT_NE(hook.primitive.find("hook"), std::string::npos);
    EXPECT_EQ(hook.cells[0].n_ix, brute_force_hook(1));
    EXPECT_EQ(hook.cells[1].n_ix, brute_force_hook(2));
}

}  // namespace
}  // namespace lat
