#include "lattice/coverage.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "lattice/face_cones.h"
#include "lattice/lattice_shape.h"
#include "lattice/octahedral.h"
#include "util/progress.h"

namespace lat {
namespace {

// The sub-rays of one pair, intersected with the given parts of the primitive (the closest hit
// of each), summed into the pair's coverage.
// Sub-rays that the renderer would snap to another pair (their exit rounds elsewhere, or they
// clip to other faces) are not the pair's rays, and are left out of its share.
template <class Parts>
CoverageSample sample_pair(const Shape& shape, const LatticeFrame& frame, const BoundaryGrid& grid,
                           double h, std::uint32_t a, std::uint32_t b, const Parts& parts) {
    const GridPoint ga = grid.point(a), gb = grid.point(b);
    int hits = 0, rays = 0;
    Vec3 psum, nsum;
    for (int k = 0; k < kCoverageRays; ++k) {
        const auto [p, q] = coverage_ray(grid, ga, gb, k);
        if (p == q) continue;  // squeezed onto a box edge: no ray
        const Ray r{p * h, (q - p) * h};
        LatticeFrame::Snap sn;
        if (!frame.snap(r, sn) || sn.a != a || sn.b != b) continue;
        ++rays;
        double best = 1.0 + 1e-12;
        Crossing bc;
        bool hit = false;
        for (const std::uint32_t part : parts) {
            Crossing c;
            if (shape.intersect_primitive(part, r, 0.0, best, c)) best = c.t, bc = c, hit = true;
        }
        if (!hit) continue;
        ++hits;
        psum += lerp(p, q, bc.t);
        nsum += shape.normal(r, bc);
    }
    CoverageSample s;
    s.a = a, s.b = b;
    if (hits == 0) return s;
    s.alpha = static_cast<float>(hits) / static_cast<float>(rays);
    const Vec3 va = to_vec(ga), d = to_vec(gb) - va;
    s.t = static_cast<float>(std::clamp(dot(psum / hits - va, d) / dot(d, d), 0.0, 1.0));
    // Opposite normals can cancel (a sub-ray bundle grazing both sides of a thin part): any
    // unit vector is then as good a mean as another, and the pair's alpha carries the weight.
    const double len = length(nsum);
    const Oct o = oct_encode(len > 1e-9 ? nsum / len : Vec3{0, 0, 1}, kRawNormalBits);
    s.nu = static_cast<std::uint16_t>(o.u), s.nv = static_cast<std::uint16_t>(o.v);
    return s;
}

struct Scratch {
    std::vector<std::vector<std::uint32_t>> parts;  // per face point: the parts it may meet
    std::vector<std::size_t> touched;
};

}  // namespace

const std::array<std::array<double, 2>, kCoverageRays>& coverage_offsets() {
    static const auto offsets = [] {
        std::array<std::array<double, 2>, kCoverageRays> o{};
        for (int i = 0; i < kCoverageRays; ++i) {
            // Hammersley: i / n on one axis, the bit-reversed i on the other, cell-centred.
            double r = 0, f = 0.5;
            for (int k = i; k; k >>= 1, f *= 0.5) r += (k & 1) * f;
            o[static_cast<std::size_t>(i)] = {(i + 0.5) / kCoverageRays - 0.5,
                                              r + 0.5 / kCoverageRays - 0.5};
        }
        return o;
    }();
    return offsets;
}

namespace {

// The axis of p's face that the direction d crosses most squarely.
std::size_t crossing_axis(const BoundaryGrid& grid, const GridPoint& p, const Vec3& d) {
    const std::uint8_t faces = grid.faces(p);
    std::size_t axis = 0;
    double best = -1;
    for (int f = 0; f < 6; ++f)
        if ((faces >> f) & 1) {
            const auto ax = static_cast<std::size_t>(BoundaryGrid::face_axis(f));
            if (std::abs(d[ax]) > best) best = std::abs(d[ax]), axis = ax;
        }
    return axis;
}

Vec3 clamp_to_box(Vec3 v, const std::array<int, 3>& n) {
    for (std::size_t k = 0; k < 3; ++k) v[k] = std::clamp(v[k], 0.0, double(n[k]));
    return v;
}

}  // namespace

SubRay coverage_ray(const BoundaryGrid& grid, const GridPoint& p, const GridPoint& q, int k) {
    const auto& off = coverage_offsets()[static_cast<std::size_t>(k)];
    return coverage_ray(grid, p, q, off[0], off[1]);
}

SubRay coverage_ray(const BoundaryGrid& grid, const GridPoint& p, const GridPoint& q, double du,
                    double dv) {
    const Vec3 vp = to_vec(p), vq = to_vec(q), d = vq - vp;
    const std::size_t ap = crossing_axis(grid, p, d), aq = crossing_axis(grid, q, d);
    Vec3 shift;
    shift[(ap + 1) % 3] = du;
    shift[(ap + 2) % 3] = dv;
    // The shifted line leaves through the plane of q's face where it meets it.
    Vec3 e = vq + shift;
    if (d[aq] != 0) e = e - d * (shift[aq] / d[aq]);
    return {clamp_to_box(vp + shift, grid.cells()), clamp_to_box(e, grid.cells())};
}

CoverageSample pair_coverage(const TableContext& ctx, std::uint32_t a, std::uint32_t b) {
    const BoundaryGrid grid(ctx.cells);
    const LatticeFrame frame(ctx, kInfinity);
    std::vector<std::uint32_t> all(ctx.primitive->primitive_count());
    std::iota(all.begin(), all.end(), 0u);
    return sample_pair(*ctx.primitive, frame, grid, ctx.cell, a, b, all);
}

std::vector<CoverageSample> rasterize_coverage(const TableContext& ctx, bool progress) {
    const Shape& shape = *ctx.primitive;
    const BoundaryGrid grid(ctx.cells);
    const LatticeFrame frame(ctx, kInfinity);
    // A sub-ray is the segment shifted by at most kSnapReach cells (its exit moved along the
    // segment when the faces differ, by a little more: one cell is kept as the margin), so a
    // part it meets has its bounding sphere, grown by that, in the cone from p_i: the culling of
    // the rasterizer with grown spheres, grouped by part in ascending order.
    const std::vector<PartSphere> cull = part_spheres(shape, ctx.cell, 1.0, 1e-9);
    std::array<FaceLayout, 6> faces;
    for (int f = 0; f < 6; ++f) faces[static_cast<std::size_t>(f)] = layout_face(grid, f);

    const std::uint32_t npoints = grid.count();
    constexpr std::uint32_t kBlock = 32;
    const std::uint32_t nblocks = (npoints + kBlock - 1) / kBlock;
    std::vector<std::vector<CoverageSample>> blocks(nblocks);
    tbb::enumerable_thread_specific<Scratch> scratch;
    ProgressBar bar("coverage", npoints, progress);
    tbb::parallel_for(std::uint32_t{0}, nblocks, [&](std::uint32_t blk) {
        Scratch& s = scratch.local();
        std::vector<CoverageSample>& out = blocks[blk];
        const std::uint32_t a_end = std::min(npoints, (blk + 1) * kBlock);
        for (std::uint32_t a = blk * kBlock; a < a_end; ++a) {
            const GridPoint ga = grid.point(a);
            const std::uint8_t fa = grid.faces(ga);
            const Vec3 p = to_vec(ga);
            for (const FaceLayout& fl : faces) {
                if (s.parts.size() < fl.mask.size()) s.parts.resize(fl.mask.size());
                for (const PartSphere& ps : cull)
                    for_each_exit_in_cone(p, ps, fl, [&](std::size_t k, const Vec3&) {
                        if (fl.ids[k] == a || !BoundaryGrid::valid_pair(fa, fl.mask[k])) return;
                        std::vector<std::uint32_t>& l = s.parts[k];
                        if (l.empty()) s.touched.push_back(k);
                        if (l.empty() || l.back() != ps.part) l.push_back(ps.part);
                    });
                for (const std::size_t k : s.touched) {
                    const CoverageSample c =
                        sample_pair(shape, frame, grid, ctx.cell, a, fl.ids[k], s.parts[k]);
                    if (c.alpha >= kCoverageMinAlpha) out.push_back(c);
                    s.parts[k].clear();
                }
                s.touched.clear();
            }
        }
        std::sort(out.begin(), out.end(), [](const CoverageSample& x, const CoverageSample& y) {
            return x.a != y.a ? x.a < y.a : x.b < y.b;
        });
        bar.add(a_end - blk * kBlock);
    });
    bar.finish();
    std::vector<CoverageSample> all;
    std::size_t n = 0;
    for (const auto& b : blocks) n += b.size();
    all.reserve(n);
    for (auto& b : blocks) all.insert(all.end(), b.begin(), b.end());
    return all;
}

}  // namespace lat
