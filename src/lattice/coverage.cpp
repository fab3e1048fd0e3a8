#include "lattice/coverage.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <numeric>

#include "geometry/chain.h"
#include "geometry/lattice_source.h"
#include "geometry/scratch_spans.h"
#include "lattice/answer_plan.h"
#include "lattice/face_cones.h"
#include "lattice/lattice_shape.h"
#include "lattice/octahedral.h"
#include "util/progress.h"

namespace lat {
namespace {

// The coverage of the pair from the hits of its own sub-rays (those snap takes to the pair).
struct Tally {
    int hits = 0, rays = 0;
    Vec3 psum, nsum;
};

CoverageSample summarise(const BoundaryGrid& grid, std::uint32_t a, std::uint32_t b, const Tally& n) {
    CoverageSample s;
    s.a = a, s.b = b;
    if (n.hits == 0) return s;
    s.alpha = static_cast<float>(n.hits) / static_cast<float>(n.rays);
    const Vec3 va = to_vec(grid.point(a)), d = to_vec(grid.point(b)) - va;
    s.t = static_cast<float>(std::clamp(dot(n.psum / n.hits - va, d) / dot(d, d), 0.0, 1.0));
    // Opposite normals can cancel (a sub-ray bundle grazing both sides of a thin part): any
    // unit vector is then as good a mean as another, and the pair's alpha carries the weight.
    const double len = length(n.nsum);
    const Oct o = oct_encode(len > 1e-9 ? n.nsum / len : Vec3{0, 0, 1}, kRawNormalBits);
    s.nu = static_cast<std::uint16_t>(o.u), s.nv = static_cast<std::uint16_t>(o.v);
    const double mean = std::min(1.0, len / n.hits);
    s.spread = static_cast<std::uint8_t>(std::lround(255 * std::sqrt(1 - mean * mean)));
    return s;
}

// The closest hit of the sub-ray (lattice units) with the given parts, added to the tally.
template <class S, class List>
void trace_sub_ray(const S& shape, double h, const SubRay& s, const List& parts, Tally& n) {
    const Ray r{s.p * h, (s.q - s.p) * h};
    Crossing bc;
    if (!first_crossing_of_parts(shape, parts, r, 0.0, 1.0 + 1e-12, bc)) return;
    ++n.hits;
    n.psum += lerp(s.p, s.q, bc.t);
    n.nsum += shape.normal(r, bc);
}

// A solid that is not the union of its parts (a CSG tree), evaluated with its listed pieces (its
// leaves, ascending) on and the others empty (Pieces::pieces_spans): along a sub-ray that the
// pieces switched off keep away from, the primitive's own crossings, bit for bit (the same
// leaves evaluated the same way, the same first crossing of their combined spans).
struct PieceSolid {
    const ShapeSource& source;
};

template <class List>
void trace_sub_ray(const PieceSolid& solid, double h, const SubRay& s, const List& on, Tally& n) {
    const Ray r{s.p * h, (s.q - s.p) * h};
    ScratchSpans spans;
    solid.source.pieces_spans(on, r, *spans);
    Crossing bc;
    if (!first_crossing(*spans, 0.0, 1.0 + 1e-12, bc)) return;
    ++n.hits;
    n.psum += lerp(s.p, s.q, bc.t);
    n.nsum += solid.source.shape().normal(r, bc);
}

// Whether snap takes the sub-ray to the pair (a, b): the definition.
bool snaps_to(const LatticeFrame& frame, double h, const SubRay& s, std::uint32_t a, std::uint32_t b) {
    const Ray r{s.p * h, (s.q - s.p) * h};
    LatticeFrame::Snap sn;
    return frame.snap(r, sn) && sn.a == a && sn.b == b;
}

// The definition: every sub-ray snapped, and intersected with the given parts (the closest hit
// of each). Sub-rays that the renderer would snap to another pair (their exit rounds
// elsewhere, or they clip to other faces) are not the pair's rays, and are left out of its share.
template <class List>
CoverageSample sample_pair(const ShapeParts& shape, const LatticeFrame& frame, const BoundaryGrid& grid,
                           double h, int rays, std::uint32_t a, std::uint32_t b,
                           const List& parts) {
    const PairRays pr(grid, grid.point(a), grid.point(b));
    Tally n;
    for (const auto& off : coverage_offsets(rays)) {
        const SubRay s = pr.ray(off[0], off[1]);
        if (s.p == s.q || !snaps_to(frame, h, s, a, b)) continue;  // squeezed onto a box edge: no ray
        ++n.rays;
        trace_sub_ray(shape, h, s, parts, n);
    }
    return summarise(grid, a, b, n);
}

}  // namespace

int coverage_rays_for(const Shape& primitive) {
    return answered_by_primitive(primitive) ? kCoverageRays : kCostlyRays;
}

bool valid_coverage_rays(int n) { return n >= 1 && n <= 1024 && std::has_single_bit(unsigned(n)); }

const std::vector<std::array<double, 2>>& coverage_offsets(int n) {
    assert(valid_coverage_rays(n));
    // Every count's, made once (a build asks for them once a pair).
    static const auto sets = [] {
        std::array<std::vector<std::array<double, 2>>, 11> all;
        for (std::size_t m = 0; m < all.size(); ++m) {
            const int count = 1 << m;
            for (int i = 0; i < count; ++i) {
                // Hammersley: i / n on one axis, the bit-reversed i on the other, cell-centred.
                double r = 0, f = 0.5;
                for (int k = i; k; k >>= 1, f *= 0.5) r += (k & 1) * f;
                all[m].push_back({(i + 0.5) / count - 0.5, r + 0.5 / count - 0.5});
            }
        }
        return all;
    }();
    return sets[static_cast<std::size_t>(std::countr_zero(unsigned(n)))];
}

SubRay coverage_ray(const BoundaryGrid& grid, const GridPoint& p, const GridPoint& q, int k, int n) {
    const auto& off = coverage_offsets(n)[static_cast<std::size_t>(k)];
    return coverage_ray(grid, p, q, off[0], off[1]);
}

SubRay coverage_ray(const BoundaryGrid& grid, const GridPoint& p, const GridPoint& q, double du,
                    double dv) {
    return PairRays(grid, p, q).ray(du, dv);
}

CoverageSample pair_coverage(const TableContext& ctx, std::uint32_t a, std::uint32_t b) {
    const BoundaryGrid grid(ctx.cells);
    const LatticeFrame frame(ctx, kInfinity);
    const ShapeParts parts(*ctx.primitive);
    std::vector<std::uint32_t> all(parts.part_count());
    std::iota(all.begin(), all.end(), 0u);
    return sample_pair(parts, frame, grid, ctx.cell, ctx.coverage_rays, a, b, all);
}

namespace {

// The build's way to the same result as sample_pair, given the parts a pair's cone culling
// left (sorted): the sub-rays' snaps guessed from their ends (PairRays::guess_snap, snap
// where it cannot tell), and the parts narrowed to those whose capsule the bundle of sub-rays
// can reach. A part left out could not be hit, and the others are tried in the same order with
// the same rays, so every hit, and the sample, is the definition's to the bit.
// A part's capsule seen along a pair's direction, in a plane across it: a sub-ray parallel to
// the pair, shifted by (du, dv), can meet the capsule only if its point w0 + du wu + dv wv there
// lies within r of the capsule's segment [0, pu].
struct Shadow {
    std::uint32_t part;
    double w0x, w0y, wux, wuy, wvx, wvy, pux, puy, uu, rr;

    bool may_meet(double du, double dv) const {
        const double wx = w0x + du * wux + dv * wvx, wy = w0y + du * wuy + dv * wvy;
        const double wu = wx * pux + wy * puy, ww = wx * wx + wy * wy;
        if (wu <= 0) return ww <= rr;
        if (wu >= uu) return uu - 2 * wu + ww <= rr;
        return ww * uu - wu * wu <= rr * uu;
    }
};

// A thread's scratch for sampling pairs.
struct PairWork {
    std::vector<std::uint32_t> near, maybe;
    std::vector<Shadow> shadows;
};

class PairSampler {
public:
    // rays: sub-rays a pair. by_pieces: the lists of parts given to sample are of pieces
    // (Pieces::piece_count), each culled by its spheres (capsules of length 0, shadows of their
    // own).
    PairSampler(const ShapeSource& shape, const LatticeFrame& frame, const BoundaryGrid& grid,
                double h, int rays, bool by_pieces)
        : frame_(frame), grid_(grid), h_(h), offsets_(coverage_offsets(rays)) {
        if (by_pieces) {
            const auto& n = grid.cells();
            const Vec3 cells{double(n[0]), double(n[1]), double(n[2])};
            for (const PartSphere& ps : piece_spheres(shape.shape(), h, cells, 0.0, 1e-9)) {
                while (piece_first_.size() <= ps.part) piece_first_.push_back(capsules_.size());
                capsules_.push_back({ps.c, ps.c, ps.r + 1e-6});
            }
            piece_first_.push_back(capsules_.size());
            return;
        }
        for (std::size_t i = 0; i < shape.parts().part_count(); ++i) {
            Capsule c;
            if (!shape.parts().part_capsule(i, c)) {
                capsules_.clear();
                break;
            }
            // Lattice units, grown by the parts' touch tolerance (a relative 1e-9 on r^2) and
            // rounding: a hit lies in the capsule.
            capsules_.push_back({c.a / h, c.b / h, c.r / h * (1 + 1e-7) + 1e-6});
        }
    }

    template <class S>
    CoverageSample sample(const S& shape, std::uint32_t a, std::uint32_t b,
                          const std::vector<std::uint32_t>& parts, PairWork& w) const {
        std::vector<std::uint32_t>& near = w.near;
        const PairRays pr(grid_, grid_.point(a), grid_.point(b));
        if (!near_parts(pr, parts, near)) return summarise(grid_, a, b, {});
        shadows(pr, near, w.shadows);
        Tally n;
        for (const auto& off : offsets_) {
            const SubRay s = pr.ray(off[0], off[1]);
            if (s.p == s.q) continue;
            const PairRays::Snap g = pr.guess_snap(s);
            if (g == PairRays::Snap::kOther ||
                (g == PairRays::Snap::kUnsure && !snaps_to(frame_, h_, s, a, b)))
                continue;
            ++n.rays;
            if (g == PairRays::Snap::kUnsure || w.shadows.empty()) {
                trace_sub_ray(shape, h_, s, near, n);
                continue;
            }
            // A guessed snap means both ends unclamped: the sub-ray runs along the shifted line.
            w.maybe.clear();
            // (A piece's shadows are consecutive: listed once.)
            for (const Shadow& sh : w.shadows)
                if ((w.maybe.empty() || w.maybe.back() != sh.part) && sh.may_meet(off[0], off[1]))
                    w.maybe.push_back(sh.part);
            if (!w.maybe.empty()) trace_sub_ray(shape, h_, s, w.maybe, n);
        }
        return summarise(grid_, a, b, n);
    }

private:
    const LatticeFrame& frame_;
    const BoundaryGrid& grid_;
    double h_;
    const std::vector<std::array<double, 2>>& offsets_;
    std::vector<Capsule> capsules_;  // per part, lattice units; empty when the shape has none
    // By pieces: piece i's capsules are [piece_first_[i], piece_first_[i + 1]) (else empty).
    std::vector<std::size_t> piece_first_;

    // The capsules of part (or piece) i.
    std::pair<std::size_t, std::size_t> capsules_of(std::uint32_t i) const {
        if (piece_first_.empty()) return {i, i + 1};
        return {piece_first_[i], piece_first_[i + 1]};
    }

    // The shadows of the near parts (none when the shape has no capsules).
    void shadows(const PairRays& pr, const std::vector<std::uint32_t>& near, std::vector<Shadow>& out) const {
        out.clear();
        if (capsules_.empty()) return;
        Vec3 b1, b2;
        orthonormal_basis(normalize(pr.dir()), b1, b2);
        const std::size_t u = pr.u_axis(), v = pr.v_axis();
        const double reach = pr.reach() + 1e-6;
        for (const std::uint32_t part : near) {
            const auto [first, last] = capsules_of(part);
            for (std::size_t k = first; k < last; ++k) {
                const Capsule& c = capsules_[k];
                // A piece's spheres away from the bundle cast no shadow it can meet.
                if (!piece_first_.empty() && !c.meets_line(pr.from(), pr.dir(), c.r + reach))
                    continue;
                const Vec3 w0 = pr.from() - c.a, pu = c.b - c.a;
                const double pux = dot(pu, b1), puy = dot(pu, b2);
                // 1e-6 more for the rounding of the projection (lattice units up to thousands).
                const double r = c.r + 1e-6;
                out.push_back({part, dot(w0, b1), dot(w0, b2), b1[u], b2[u], b1[v], b2[v], pux,
                               puy, pux * pux + puy * puy, r * r});
            }
        }
    }

    // The parts (of `parts`, in order) that a sub-ray can meet: those whose capsule comes within
    // the bundle's reach of the pair's line. False when there is none.
    bool near_parts(const PairRays& pr, const std::vector<std::uint32_t>& parts,
                    std::vector<std::uint32_t>& near) const {
        near.clear();
        if (capsules_.empty()) {
            near = parts;
            return !near.empty();
        }
        const double reach = pr.reach() + 1e-6;
        for (const std::uint32_t part : parts) {
            const auto [first, last] = capsules_of(part);
            for (std::size_t k = first; k < last; ++k) {
                const Capsule& c = capsules_[k];
                if (c.meets_line(pr.from(), pr.dir(), c.r + reach)) {
                    near.push_back(part);
                    break;
                }
            }
        }
        return !near.empty();
    }
};

struct Scratch {
    std::vector<std::vector<std::uint32_t>> parts;  // per face point: the parts it may meet
    std::vector<std::size_t> touched;
    PairWork work;
};

// The pairs whose sub-rays can meet the primitive, found by culling: a sub-ray is the segment
// shifted by at most kSnapReach cells (its exit moved along the segment when the faces differ,
// by a little more: one cell is kept as the margin), so a part it meets has its bounding sphere,
// grown by that, in the cone from p_i: the culling of the rasterizer with grown spheres, grouped
// by part in ascending order.
// A CSG tree's primitive is the whole tree, whose sphere is the box's: it is culled by its
// pieces (leaves) instead, and each pair's sub-rays evaluate the leaves near it alone
// (PieceSolid). Of the pairs of a CSG of six tori minus a sphere (the burr of the
// costly-primitive bench), most come near one or two leaves, or none.
class PairCuller {
public:
    explicit PairCuller(const TableContext& ctx)
        : grid_(ctx.cells) {
        const ShapeSource shape(*ctx.primitive);
        by_pieces_ = !shape.pieces_are_union() && shape.piece_count() > 1;
        const Vec3 cells{double(ctx.cells[0]), double(ctx.cells[1]), double(ctx.cells[2])};
        cull_ = by_pieces_ ? piece_spheres(shape.shape(), ctx.cell, cells, 1.0, 1e-9)
                           : part_spheres(shape.shape(), ctx.cell, 1.0, 1e-9);
        for (int f = 0; f < 6; ++f) faces_[static_cast<std::size_t>(f)] = layout_face(grid_, f);
    }

    const BoundaryGrid& grid() const { return grid_; }
    // Whether the parts are the primitive's pieces (Pieces::piece_count), not its parts.
    bool by_pieces() const { return by_pieces_; }

    // visit(b, parts) for every pair (a, b) that some culling sphere keeps, with the parts
    // (ascending) whose spheres keep it.
    template <class Visit>
    void pairs(std::uint32_t a, Scratch& s, Visit&& visit) const {
        const GridPoint ga = grid_.point(a);
        const std::uint8_t fa = grid_.faces(ga);
        const Vec3 p = to_vec(ga);
        for (const FaceLayout& fl : faces_) {
            if (s.parts.size() < fl.mask.size()) s.parts.resize(fl.mask.size());
            for (const PartSphere& ps : cull_)
                for_each_exit_in_cone(p, ps, fl, [&](std::size_t k, const Vec3&) {
                    if (fl.ids[k] == a || !BoundaryGrid::valid_pair(fa, fl.mask[k])) return;
                    std::vector<std::uint32_t>& l = s.parts[k];
                    if (l.empty()) s.touched.push_back(k);
                    if (l.empty() || l.back() != ps.part) l.push_back(ps.part);
                });
            for (const std::size_t k : s.touched) {
                visit(fl.ids[k], s.parts[k]);
                s.parts[k].clear();
            }
            s.touched.clear();
        }
    }

private:
    BoundaryGrid grid_;
    bool by_pieces_;
    std::vector<PartSphere> cull_;
    std::array<FaceLayout, 6> faces_;
};

}  // namespace

std::vector<CoverageSample> rasterize_coverage(const TableContext& ctx, bool progress) {
    const ShapeSource shape(*ctx.primitive);
    const PairCuller culler(ctx);
    const BoundaryGrid& grid = culler.grid();
    const LatticeFrame frame(ctx, kInfinity);
    const PairSampler sampler(shape, frame, grid, ctx.cell, ctx.coverage_rays, culler.by_pieces());
    // Chains (the common primitive) are traced through their concrete type, without virtual
    // calls in the innermost loop.
    const ChainShape* chain = as_chain(shape.shape());

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
        for (std::uint32_t a = blk * kBlock; a < a_end; ++a)
            culler.pairs(a, s, [&](std::uint32_t b, const std::vector<std::uint32_t>& parts) {
                const CoverageSample c =
                    chain                ? sampler.sample(*chain, a, b, parts, s.work)
                    : culler.by_pieces() ? sampler.sample(PieceSolid{shape}, a, b, parts, s.work)
                                         : sampler.sample(shape.parts(), a, b, parts, s.work);
                if (c.alpha >= kCoverageMinAlpha) out.push_back(c);
            });
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

CoverageWork coverage_work_parts(const TableContext& ctx) {
    const ShapeSource shape(*ctx.primitive);
    const PairCuller culler(ctx);
    // A part costs its share of the primitive's cost, at least one simple test (a chain's
    // sphere or cylinder, a mesh's triangle; a CSG tree's leaf, a quartic about 12).
    const double parts = culler.by_pieces() ? static_cast<double>(shape.piece_count())
                                            : static_cast<double>(shape.parts().part_count());
    const double per_part = std::max(1.0, shape.intersect_cost() / std::max(1.0, parts));
    // Counted on about kSampled entry points spread evenly: the culling alone, under half a
    // second at sigma^-1 = 4 for the burr of the costly-primitive bench. 64 points read its
    // work 13 % low there; 256 and 512 gave the same.
    constexpr std::uint32_t kSampled = 256;
    const std::uint32_t npoints = culler.grid().count();
    const std::uint32_t stride = std::max<std::uint32_t>(1, npoints / kSampled);
    Scratch s;
    CoverageWork w;
    std::uint32_t sampled = 0;
    for (std::uint32_t a = 0; a < npoints; a += stride, ++sampled)
        culler.pairs(a, s, [&](std::uint32_t, const std::vector<std::uint32_t>& near) {
            w.pairs += 1;
            w.part_tests += static_cast<double>(near.size()) * per_part;
        });
    const double scale = static_cast<double>(npoints) / std::max<std::uint32_t>(1, sampled);
    w.pairs *= scale;
    w.part_tests *= scale;
    return w;
}

double coverage_work(const TableContext& ctx) {
    const CoverageWork w = coverage_work_parts(ctx);
    return (ctx.coverage_rays + kPairOverheadRays) * (w.pairs * kSubRayOverheadTests + w.part_tests);
}

double coverage_cpu_seconds(const TableContext& ctx) {
    return coverage_work(ctx) / kCoverageTestsPerCpuSecond;
}

}  // namespace lat
