#pragma once
// Coverage: a lattice answers every ray that snaps to a pair (p_i, p_o) with that
// pair's entry, so the entry should describe all those rays, not only the one through both grid
// points. Per ordered pair this computes, from sub-rays parallel to the segment p_i p_o and
// shifted over the face cell of p_i, the share alpha that meets the primitive and the mean of
// their hit points and normals. Prefiltered tables (encodings with Encoding::coverage) store it.
//
// Why parallel shifts and not every pairing of entry and exit offsets: the shifts of a cell
// tile the plane, so over the pairs (i, i + k) of one direction every point of the primitive is
// counted exactly once and the image keeps the primitive's true area; with independent end
// offsets the sub-rays bunch up near the grid lines, and a primitive thinner than a cell came
// out 3-5 % too bright or too dark depending on where it lay on the grid.
#include <array>
#include <cstdint>
#include <vector>

#include "lattice/boundary_grid.h"
#include "lattice/coverage_rays.h"
#include "lattice/table.h"

namespace lat {

// Sub-rays a pair is sampled with (TableContext::coverage_rays): kCoverageRays (lattice/table.h),
// or for a primitive costly to intersect, kCostlyRays. A costly primitive's build pays
// for every sub-ray a solve of its leaves (quartics for a CSG of tori), and its parts are
// solids wider than a cell, whose pairs are mostly covered or not at all: for the burr of the
// complexity bench (six tori minus a sphere) 16 sub-rays built 3.1 times faster than 64, for
// 0.04 dB less at sigma^-1 = 4 and nothing measurable at 2. Thin hair, whose pairs carry
// partial coverage, keeps 64 (and is cheap to intersect).
inline constexpr int kCostlyRays = 16;
// The count for a primitive's tables: the one place it is chosen. Costly means what it means to
// the answer plan (lattice/answer_plan.h: not answered_by_primitive).
int coverage_rays_for(const Shape& primitive);
// Counts a table may have: powers of two (the offsets then form a net, below) up to 1024.
bool valid_coverage_rays(int n);
// Pairs with a smaller share are left out (unless their own segment hits): 1/32 is about one
// 8-bit step on the edge of a hair.
inline constexpr float kCoverageMinAlpha = 1.0f / 32;

// One ordered pair's coverage.
struct CoverageSample {
    std::uint32_t a = 0, b = 0;
    float alpha = 0;         // the share of the pair's sub-rays that meet the primitive
    float t = 0;             // the mean hit point, projected on the segment p_a -> p_b
    // The normalised mean of the hits' unit normals, octahedral in kRawNormalBits bits a
    // component (tens of millions of samples are kept while a fine table is built).
    std::uint16_t nu = 0, nv = 0;
    // How far the hits' unit normals spread about that mean: sqrt(1 - len^2) for a mean of
    // length len, in 1/255 (0: all alike). A thin hair seen across a cell shows the half of
    // it that faces the ray, whose normals' mean is about pi/4 long: the shading needs it
    // (render/core/shading.h: diffuse_mean) and the direction alone would lose it.
    std::uint8_t spread = 0;
};

// The n shifts (in cells, each coordinate in (-1/2, 1/2)) of the sub-rays on the entry face
// cell: a Hammersley set, fixed, so that tables depend on nothing but the lattice and n. For n
// a power of two it is a (0, m, 2)-net: every box of the cell's 2^m equal boxes of the
// power-of-two shapes (n x 1, n/2 x 2, ..., 1 x n) holds one shift, so each count samples the
// cell evenly, and the tiling above holds for any count. n: valid_coverage_rays.
const std::vector<std::array<double, 2>>& coverage_offsets(int n);

// Sub-ray k (0 <= k < n) of the n of the pair (p, q), lattice units: the segment shifted by
// the k-th offset within the face of p that it crosses most squarely, from that face's plane to
// the plane of q's face (the one it crosses most squarely), its ends kept on the box
// (PairRays::ray).
SubRay coverage_ray(const BoundaryGrid& grid, const GridPoint& p, const GridPoint& q, int k, int n);
// The same for any shift (du, dv) along the face's next two axes (x -> y, z; y -> z, x; z -> x, y).
SubRay coverage_ray(const BoundaryGrid& grid, const GridPoint& p, const GridPoint& q, double du,
                    double dv);

// The coverage of one pair by intersecting every sub-ray (ctx.coverage_rays of them) with the
// whole primitive: the definition, for tests and small checks.
CoverageSample pair_coverage(const TableContext& ctx, std::uint32_t a, std::uint32_t b);

// Every ordered pair with alpha >= kCoverageMinAlpha, sorted by (a, b); parallel over entry
// points, the same for any thread count. ctx.primitive must be set.
std::vector<CoverageSample> rasterize_coverage(const TableContext& ctx, bool progress);

// About the work of a coverage table's build, in simple tests (a sphere's, a cylinder's): for
// each pair the build samples (those its culling keeps) and each of its sub-rays, the tests of
// the parts culled near the pair (for a CSG tree, its leaves; a part weighs its share of the
// primitive's intersect_cost, at least 1), plus kSubRayOverheadTests for the sub-ray itself
// (its snap, the parts' shadows); and as much again for kPairOverheadRays more sub-rays a pair,
// the work that does not grow with them (the pair's own segment, rasterized for its hit; its
// culling and shadows). Counted on a sample of the entry points. ctx.primitive must be set.
double coverage_work(const TableContext& ctx);
// Its parts, for one sub-ray a pair: pairs sampled and part tests.
struct CoverageWork {
    double pairs = 0, part_tests = 0;
};
CoverageWork coverage_work_parts(const TableContext& ctx);
// What a build does in a second of one core, and its costs besides its parts' tests: fitted to
// the builds of bench/notes/complexity-log.md (CSGs of 1, 4 and 12 quartics, the burr, the
// Plate 3 hair; 16 and 64 sub-rays a pair; 2.5 GHz Xeon): within 25 % of the CPU time
// measured (the burr 14 to 23 % low: its thin rings' many bounding spheres, each a shadow test
// a sub-ray).
inline constexpr double kCoverageTestsPerCpuSecond = 1.0e8;
inline constexpr double kSubRayOverheadTests = 1.0;
inline constexpr double kPairOverheadRays = 8.0;
// The estimated CPU seconds of one core for the build.
double coverage_cpu_seconds(const TableContext& ctx);

}  // namespace lat
