#include "lattice/rasterizer.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstring>
#include <span>
#include <stdexcept>
#include <type_traits>

#include "distributed/deal.h"
#include "distributed/job.h"
#include "distributed/message.h"
#include "distributed/timeline.h"
#include "geometry/chain.h"
#include "geometry/ray_fan.h"
#include "lattice/boundary_grid.h"
#include "lattice/face_cones.h"
#include "lattice/octahedral.h"
#include "util/error.h"
#include "util/progress.h"

namespace lat {
namespace {

constexpr std::uint32_t kBlock = 32;  // entry points per task



// A hit records its part and CSG leaf in 16 and 15 bits (RawHit): a primitive whose crossings
// are numbered beyond cannot have a hit table (its normals would come from another part).
[[noreturn]] void refuse_part(const Crossing& c) {
    throw InputError("a hit on part number " + std::to_string(c.part) + ", leaf " +
                     std::to_string(c.leaf_index()) + ": hit tables record parts up to " +
                     std::to_string(RawHit::kMaxPart) + " (a chain of at most 16,384 spheres and " +
                     "cylinders) and leaves up to " + std::to_string(RawHit::kMaxLeaf) +
                     "; use the candidates encoding, or split the primitive");
}

struct Counts {
    std::uint64_t enumerated = 0, traced = 0, hits = 0, counted = 0, tests = 0;
};

// Per-thread output: hits go into large buffers; a block's hits stay contiguous. Small pages:
// the hits are written once in order and read chunk by chunk, so huge pages would save few TLB
// misses, and on a virtual machine that hands freed memory back to its host (free page
// reporting) a huge page touched first costs several times its 512 small pages.
template <class Hit>
class HitArena {
public:
    static constexpr std::size_t kHits = std::size_t{4} << 20;  // 80 MB of raw hits per buffer

    void begin_block() { block_start_ = used_; }
    void push(const Hit& h) {
        if (used_ == cap_) grow();
        cur_[used_++] = h;
    }
    std::span<const Hit> end_block() const { return {cur_ + block_start_, used_ - block_start_}; }
    std::vector<std::shared_ptr<const ByteBuffer>>& buffers() { return buffers_; }

private:
    std::vector<std::shared_ptr<const ByteBuffer>> buffers_;
    Hit* cur_ = nullptr;
    std::size_t used_ = 0, cap_ = 0, block_start_ = 0;

    void grow() {
        // Move the unfinished block to the new buffer so that it stays in one piece.
        const std::size_t partial = used_ - block_start_;
        const std::size_t cap = std::max(kHits, 2 * partial);
        auto buf = std::make_shared<ByteBuffer>(cap * sizeof(Hit), ByteBuffer::Pages::kSmall);
        auto* next = reinterpret_cast<Hit*>(buf->data());
        std::copy(cur_ + block_start_, cur_ + used_, next);
        buffers_.push_back(buf);
        cur_ = next, cap_ = cap, used_ = partial, block_start_ = 0;
    }
};

// A chain's crossings are a t and a part alone, kept as its part (Scratch::best_part); other
// shapes keep the whole crossing (best_c).
template <class S>
inline constexpr bool kKeepsPartOnly = std::is_same_v<S, ChainShape>;

struct Scratch {
    std::vector<double> best_t;
    // The closest crossing so far at each point: its t in best_t; for a chain, whose crossings
    // are t and a part alone, its part in best_part, else the whole crossing in best_c.
    std::vector<Crossing> best_c;
    std::vector<std::uint32_t> best_part;
    std::vector<std::uint32_t> tested;  // generation of the last part tested at each point
    std::uint32_t generation = 0;
    // The face points with a hit, to emit and reset: the first n_touched of touched, which has
    // room for every point of a face and one more (a point is written, then counted if new).
    std::vector<std::uint32_t> touched;
    std::size_t n_touched = 0;
    // The u-range of exits that the last sphere visited in each row of a face, stamped with
    // that sphere's visit (the next sphere of the same part skips them: they are gathered).
    struct RowRange {
        std::uint64_t visit = 0;
        int ub = 0, ue = -1;
    };
    std::vector<RowRange> rows;
    std::uint64_t visit = 0;
    // The exits in the cones of one part, to test against it: each one's index in the face, its
    // segment's direction (primitive units) and the end of its range, in arrays of their own
    // (two lanes load as one register). Each exit is gathered once, so a face's size holds them
    // (trace_face fills them).
    struct Batch {
        std::vector<std::uint32_t> k;
        std::vector<double> dx, dy, dz, tmax;
        std::size_t n = 0;
        void fit(std::size_t size) {
            k.resize(size), dx.resize(size), dy.resize(size), dz.resize(size), tmax.resize(size);
        }
    } batch;
    // A face's hits on their way to the arena (Tracer::keep_hits): their exits, then their
    // normals, t, parts and leaves.
    struct Emit {
        std::vector<std::uint32_t> k;
        std::vector<Vec3> n;
        std::vector<float> t;
        std::vector<std::uint16_t> part, leaf;
        void fit(std::size_t size) { k.resize(size), n.resize(size), t.resize(size), part.resize(size), leaf.resize(size); }
    } emit;
    bool point_hits = false;  // hits kept in `points`, else in `raw`
    HitArena<RawHit> raw;
    HitArena<PointHit> points;
};

// The primitive as a Shape, for the tracer's loops over its parts (a chain's concrete type, or
// any shape's ShapeParts).
const Shape& whole_shape(const ChainShape& chain) { return chain; }
const Shape& whole_shape(const ShapeParts& parts) { return parts.shape(); }

// Everything about the lattice that does not depend on the entry point.
class Tracer {
public:
    Tracer(const Shape& shape, const TableContext& lg) : grid_(lg.cells), h_(lg.cell) {
        for (int f = 0; f < 6; ++f) {
            const FaceLayout& fl = faces_[static_cast<std::size_t>(f)] = layout_face(grid_, f);
            std::vector<Vec3>& at = points_[static_cast<std::size_t>(f)];
            for (const std::uint32_t id : fl.ids) at.push_back(to_vec(grid_.point(id)));
        }
        count_sums();
        // Padded beyond the parts' touch tolerance so culling never drops a touching hit.
        spheres_ = part_spheres(shape, h_, 0.0, 1e-6);
    }

    const BoundaryGrid& grid() const { return grid_; }

    // All exits from entry point a: tests, counts and (with keep) the hits.
    template <class S>
    void trace_entry(const S& shape, std::uint32_t a, bool keep, Scratch& s, Counts& cnt) const {
        const GridPoint gp = grid_.point(a);
        const std::uint8_t fa = grid_.faces(gp);
        const Vec3 p = to_vec(gp);
        // Eq. (2) also counts a point paired with itself on two of its faces.
        const int nf = __builtin_popcount(fa);
        cnt.enumerated += static_cast<std::uint64_t>(nf * nf - nf);
        const bool start_inside = shape.inside(p * h_);
        for (int f = 0; f < 6; ++f) {
            const FaceLayout& fl = faces_[static_cast<std::size_t>(f)];
            const std::vector<Vec3>& at = points_[static_cast<std::size_t>(f)];
            if (s.best_t.size() < fl.mask.size()) {
                s.best_t.assign(fl.mask.size(), kInfinity);
                if constexpr (kKeepsPartOnly<S>) s.best_part.resize(fl.mask.size());
                else s.best_c.resize(fl.mask.size());
                s.tested.assign(fl.mask.size(), 0);
                s.touched.resize(fl.mask.size() + 1);
                s.emit.fit(fl.mask.size());
                s.batch.fit(fl.mask.size());
            }
            if (start_inside) {  // every segment starts in the solid: all hit at t = 0
                for (std::size_t k = 0; k < fl.mask.size(); ++k)
                    if (fl.canonical[k]) s.touched[s.n_touched++] = static_cast<std::uint32_t>(k);
            } else {
                trace_face(shape, p, fl, s, cnt);
            }
            // Counts over the whole face from per-mask tallies; hits from the touched list.
            const bool own = __builtin_ctz(fa) == f && BoundaryGrid::valid_pair(fa, fa);
            cnt.enumerated += sums_[fa][static_cast<std::size_t>(f)].multiplicity -
                              (own ? static_cast<std::uint64_t>(BoundaryGrid::multiplicity(fa, fa)) : 0);
            cnt.traced += sums_[fa][static_cast<std::size_t>(f)].valid - (own ? 1 : 0);
            const std::span<const std::uint32_t> touched(s.touched.data(), s.n_touched);
            std::size_t n_keep = 0;
            for (const std::size_t k : touched) {
                if (fl.ids[k] == a || !BoundaryGrid::valid_pair(fa, fl.mask[k])) continue;
                ++cnt.hits;
                cnt.counted += static_cast<std::uint64_t>(BoundaryGrid::multiplicity(fa, fl.mask[k]));
                s.emit.k[n_keep++] = static_cast<std::uint32_t>(k);
            }
            if (keep) keep_hits(shape, a, p, fl, at, start_inside, s, n_keep);
            if (!start_inside)
                for (const std::size_t k : touched) s.best_t[k] = kInfinity;
            s.n_touched = 0;
        }
    }

private:
    BoundaryGrid grid_;
    double h_;
    std::array<FaceLayout, 6> faces_;
    std::array<std::vector<Vec3>, 6> points_;  // each face point's coordinates (lattice units)
    struct Sum {
        std::uint64_t valid = 0, multiplicity = 0;
    };
    std::array<std::array<Sum, 6>, 64> sums_{};
    std::vector<PartSphere> spheres_;

    // For every face mask of an entry point and every exit face: how many exit points there
    // make a valid pair, and how many face pairs they stand for (the paper's count).
    void count_sums() {
        for (int f = 0; f < 6; ++f) {
            std::array<std::uint64_t, 64> tally{};
            const FaceLayout& fl = faces_[static_cast<std::size_t>(f)];
            for (std::size_t k = 0; k < fl.mask.size(); ++k)
                if (fl.canonical[k]) ++tally[fl.mask[k]];
            for (std::uint8_t fa = 1; fa < 64; ++fa)
                for (std::uint8_t m = 1; m < 64; ++m) {
                    if (!tally[m] || !BoundaryGrid::valid_pair(fa, m)) continue;
                    Sum& sum = sums_[fa][static_cast<std::size_t>(f)];
                    sum.valid += tally[m];
                    sum.multiplicity += tally[m] * static_cast<std::uint64_t>(BoundaryGrid::multiplicity(fa, m));
                }
        }
    }

    // The closest hit of every segment from p to face fl, culled per part by its cones: the
    // exits in any cone of a part are gathered (each once), then tested against it. Exits are
    // gathered in the order of the part's spheres, rows and u, which fixes the order of the hits.
    template <class S>
    void trace_face(const S& shape, const Vec3& p, const FaceLayout& fl, Scratch& s, Counts& cnt) const {
        if (s.rows.size() < static_cast<std::size_t>(fl.nv)) s.rows.resize(static_cast<std::size_t>(fl.nv));
        Scratch::Batch& b = s.batch;
        // An exit's segment is q - p in primitive units, q's coordinates small integers: along
        // the face's axis and v it is the same for a whole face and row, along u one subtraction.
        double* const along[3] = {b.dx.data(), b.dy.data(), b.dz.data()};
        double* const du = along[static_cast<std::size_t>(fl.ua)];
        double* const dv = along[static_cast<std::size_t>(fl.va)];
        double* const dax = along[static_cast<std::size_t>(fl.axis)];
        const double pu = p[static_cast<std::size_t>(fl.ua)], pv = p[static_cast<std::size_t>(fl.va)];
        const double dax_face = (fl.level - p[static_cast<std::size_t>(fl.axis)]) * h_;
        // The (canonical) exits [ub, ue] of row v (from index k0 = v nu) into the batch; with
        // marks, those not yet gathered for this part. An exit's range ends at its best hit so far, which
        // only its own test in this part's batch can change.
        const auto gather = [&](std::size_t k0, double dv_row, int ub, int ue, bool marks) {
            for (int u = ub; u <= ue; ++u) {
                const std::size_t k = k0 + static_cast<std::size_t>(u);
                if (marks) {
                    if (s.tested[k] == s.generation) continue;
                    s.tested[k] = s.generation;
                }
                assert(b.n < b.k.size());
                b.k[b.n] = static_cast<std::uint32_t>(k);
                du[b.n] = (u - pu) * h_, dv[b.n] = dv_row, dax[b.n] = dax_face;
                b.tmax[b.n] = std::min(s.best_t[k], 1.0 + 1e-12);
                ++b.n;
            }
        };
        std::uint32_t last_part = ~0u;
        b.n = 0;
        for (std::size_t i = 0; i < spheres_.size(); ++i) {
            const PartSphere& ps = spheres_[i];
            const bool first = ps.part != last_part;
            if (first) {
                test_batch(shape, p, last_part, s, cnt);
                last_part = ps.part;
                ++s.generation;  // marks "gathered for this part" in s.tested
            }
            // A part of one sphere visits each exit once: it needs no marks.
            const bool alone = first && (i + 1 == spheres_.size() || spheres_[i + 1].part != ps.part);
            const std::uint64_t visit = ++s.visit;
            for_each_cone_row(p, ps, fl, [&](int v, int ub, int ue) {
                const std::size_t k0 = static_cast<std::size_t>(v) * static_cast<std::size_t>(fl.nu);
                const double dv_row = (v - pv) * h_;
                if (alone) return gather(k0, dv_row, ub, ue, false);
                // What the part's previous sphere visited in this row is gathered already.
                Scratch::RowRange& row = s.rows[static_cast<std::size_t>(v)];
                const Scratch::RowRange before = row;
                row = {visit, ub, ue};
                if (first || before.visit + 1 != visit || before.ue < ub || before.ub > ue)
                    return gather(k0, dv_row, ub, ue, true);
                gather(k0, dv_row, ub, before.ub - 1, true);
                gather(k0, dv_row, before.ue + 1, ue, true);
            });
        }
        test_batch(shape, p, last_part, s, cnt);
    }

    // Each gathered exit's segment from p against the part, keeping the closest hit (ties to
    // the earlier part: only a crossing before the best so far counts). Every exit appears
    // once, so the order of the tests does not matter.
    template <class S>
    void test_batch(const S& shape, const Vec3& p, std::uint32_t part, Scratch& s, Counts& cnt) const {
        Scratch::Batch& b = s.batch;
        cnt.tests += b.n;
        const auto keep = [&](std::size_t k, const Crossing& c) {
            // Counted without a branch: whether an exit is hit for the first time is hard to
            // predict.
            s.touched[s.n_touched] = static_cast<std::uint32_t>(k);
            s.n_touched += s.best_t[k] == kInfinity;
            s.best_t[k] = c.t;
            if constexpr (kKeepsPartOnly<S>) s.best_part[k] = c.part;
            else s.best_c[k] = c;
        };
        std::size_t i = 0;
        if constexpr (std::is_same_v<S, ChainShape>) {
            // Two segments at a time (geometry/ray_fan.h), each lane as the scalar test; a run
            // of pairs is tested before any of its hits is kept, so that no branch on a pair's
            // answer (which is hard to predict) stands between the tests of the next pairs.
            // Every exit appears once, so no test's range depends on a hit kept in the run.
            constexpr std::size_t kRun = 16;
            RayFan f;
            f.o = p * h_;
            f.tmin = _mm_setzero_pd();
            static_assert(2 * kRun <= 32);
            alignas(16) double t[2 * kRun], sub[2 * kRun];
            while (i + 1 < b.n) {
                const std::size_t run = std::min(kRun, (b.n - i) / 2);
                std::uint32_t met = 0;  // bit j: lane j of the run has a hit
                for (std::size_t r = 0; r < run; ++r) {
                    const std::size_t e = i + 2 * r;  // even: the arrays' 16-byte alignment
                    f.d = {_mm_load_pd(&b.dx[e]), _mm_load_pd(&b.dy[e]), _mm_load_pd(&b.dz[e])};
                    f.tmax = _mm_load_pd(&b.tmax[e]);
                    FanHits out;
                    met |= shape.intersect_fan(part, f, out) << (2 * r);
                    _mm_store_pd(t + 2 * r, out.t);
                    _mm_store_pd(sub + 2 * r, out.part);
                }
                // The hits in lane order, one branch each (a branch per lane mispredicts).
                for (; met; met &= met - 1) {
                    const auto j = static_cast<std::size_t>(__builtin_ctz(met));
                    keep(b.k[i + j], Crossing(t[j], part << 2 | static_cast<std::uint32_t>(sub[j]), 0));
                }
                i += 2 * run;
            }
        }
        for (; i < b.n; ++i) {
            const Ray r{p * h_, {b.dx[i], b.dy[i], b.dz[i]}};
            Crossing c;
            if (shape.intersect_part(part, r, 0.0, b.tmax[i], c)) keep(b.k[i], c);
        }
        b.n = 0;
    }

    // The hits of segments from a to the face's exits e.k[0, n) into the thread's arena: raw,
    // or as PointHits (made straight from their parts: the rasterizer's every hit passes here).
    // First every hit's crossing and normal, then their codes: a normal is a long chain of
    // divisions, and short loops let the chains of several hits overlap.
    template <class S>
    void keep_hits(const S& shape, std::uint32_t a, const Vec3& p, const FaceLayout& fl,
                   const std::vector<Vec3>& at, bool start_inside, Scratch& s, std::size_t n) const {
        Scratch::Emit& e = s.emit;
        for (std::size_t j = 0; j < n; ++j) {
            const std::size_t k = e.k[j];
            const Ray r{p * h_, (at[k] - p) * h_};
            Crossing c;
            if constexpr (kKeepsPartOnly<S>) c = Crossing(s.best_t[k], s.best_part[k], 0);
            else c = s.best_c[k];
            float t = static_cast<float>(std::min(1.0, s.best_t[k]));
            if (start_inside) {
                // p lies in the closed solid (on its surface, where a primitive touches the box):
                // the hit is p itself, with the surface there the crossing nearest to it.
                t = 0.0f;
                c = nearest_crossing(whole_shape(shape), r);
            }
            if (c.part > RawHit::kMaxPart || c.leaf_index() > RawHit::kMaxLeaf) refuse_part(c);
            e.n[j] = shape.normal(r, c);
            e.t[j] = t;
            e.part[j] = static_cast<std::uint16_t>(c.part);
            e.leaf[j] = RawHit::pack_leaf(c.leaf);
        }
        for (std::size_t j = 0; j < n; ++j) {
            const Oct o = oct_encode(e.n[j], kRawNormalBits);
            const auto nu = static_cast<std::uint16_t>(o.u), nv = static_cast<std::uint16_t>(o.v);
            const std::uint32_t b = fl.ids[e.k[j]];
            if (!s.point_hits) {
                s.raw.push({a, b, e.t[j], nu, nv, e.part[j], e.leaf[j]});
                continue;
            }
            // The table's build checked every id against the encoding's limit before tracing.
            if (a >= 0xFFFF || b >= 0xFFFF) throw std::length_error("point hits: point id over 16 bits");
            s.points.push({static_cast<std::uint16_t>(a), static_cast<std::uint16_t>(b), quantise_t16(e.t[j]), nu, nv});
        }
    }
};

// Rank 0 receives every other rank's blocks: their ids, counts and hit counts, then the hits
// (which stay in the received buffer, as one more storage of the result).
void gather_blocks(const dist::DealReport& mine, bool keep_hits, std::vector<Counts>& counts,
                   std::vector<std::span<const RawHit>>& hits,
                   std::vector<std::shared_ptr<const ByteBuffer>>& storage) {
    std::vector<std::uint32_t> ids;
    for (const auto& [begin, end] : mine.chunks)
        for (std::uint32_t blk = begin; blk != end; ++blk) ids.push_back(blk);
    const std::uint64_t n = ids.size();
    std::vector<Counts> my_counts;
    std::vector<std::uint64_t> sizes;
    for (const std::uint32_t blk : ids) {
        my_counts.push_back(counts[blk]);
        sizes.push_back(keep_hits ? hits[blk].size() : 0);
    }
    const auto bytes = [](const auto& v) {
        return std::span(reinterpret_cast<const std::uint8_t*>(v.data()), v.size() * sizeof(v[0]));
    };
    std::vector<std::span<const std::uint8_t>> pieces{
        {reinterpret_cast<const std::uint8_t*>(&n), sizeof n}, bytes(ids), bytes(my_counts), bytes(sizes)};
    if (keep_hits)
        for (const std::uint32_t blk : ids) pieces.push_back(bytes(hits[blk]));
    std::vector<ByteBuffer> all = dist::gather_to_root(pieces);
    if (!dist::is_root()) return;
    // What the other ranks sent is checked before it is used: every block from exactly one
    // rank, hit counts that fill the message exactly.
    std::vector<bool> dealt(counts.size());
    dist::mark_dealt(mine.chunks, dealt, dist::MessageReader({}, "block list", 0));
    for (std::size_t r = 1; r < all.size(); ++r) {
        auto buffer = std::make_shared<ByteBuffer>(std::move(all[r]));
        dist::MessageReader in({buffer->data(), buffer->size()}, "rasterized blocks", static_cast<int>(r));
        const std::uint64_t m = in.read<std::uint64_t>();
        const auto list = [&](auto& v) {  // m values, checked to fit before they are allocated
            const std::span<const std::uint8_t> b = in.take(m, sizeof(v[0]));
            v.resize(m);
            if (m) std::memcpy(v.data(), b.data(), b.size());
        };
        std::vector<std::uint32_t> their_ids;
        std::vector<Counts> their_counts;
        std::vector<std::uint64_t> their_sizes;
        list(their_ids);
        list(their_counts);
        list(their_sizes);
        for (std::size_t i = 0; i < m; ++i) {
            const std::uint32_t blk = their_ids[i];
            const dist::Chunk one{blk, blk + 1};
            dist::mark_dealt(std::span(&one, 1), dealt, in);
            counts[blk] = their_counts[i];
            if (!keep_hits) continue;
            // 4-byte aligned: every field before the hits is a multiple of 4 bytes.
            const std::span<const std::uint8_t> b = in.take(their_sizes[i], sizeof(RawHit));
            hits[blk] = {reinterpret_cast<const RawHit*>(b.data()), their_sizes[i]};
        }
        in.expect_end();
        storage.push_back(std::move(buffer));
    }
    for (std::size_t b = 0; b < dealt.size(); ++b)
        if (!dealt[b]) throw dist::MessageError("block " + std::to_string(b) + " came from no rank");
}

}  // namespace

RasterizeResult rasterize(const TableContext& ctx, const RasterizeOptions& opt) {
    assert(ctx.primitive);
    const auto start = std::chrono::steady_clock::now();
    const Shape& shape = *ctx.primitive;
    const Tracer tracer(shape, ctx);
    // Chains (the common primitive) are traced through their concrete type, without virtual
    // calls in the innermost loop.
    const ChainShape* chain = as_chain(shape);
    const ShapeParts parts(shape);

    const std::uint32_t npoints = tracer.grid().count();
    const std::uint32_t nblocks = (npoints + kBlock - 1) / kBlock;
    assert(!(opt.point_hits && opt.across_ranks && dist::distributed()));
    const bool keep_raw = opt.keep_hits && !opt.point_hits;
    const bool keep_points = opt.keep_hits && opt.point_hits;
    std::vector<std::span<const RawHit>> block_hits(keep_raw ? nblocks : 0);
    std::vector<std::span<const PointHit>> block_points(keep_points ? nblocks : 0);
    std::vector<Counts> block_counts(nblocks);
    tbb::enumerable_thread_specific<Scratch> scratch;
    ProgressBar bar("rasterize", nblocks, opt.progress && dist::is_root());

    dist::DealOptions deal_opt;
    deal_opt.across_ranks = opt.across_ranks && dist::distributed();
    deal_opt.progress = &bar;
    const dist::DealReport deal = dist::deal(nblocks, [&](std::uint32_t blk) {
        Scratch& s = scratch.local();
        s.point_hits = opt.point_hits;
        Counts cnt;
        s.raw.begin_block();
        s.points.begin_block();
        const std::uint32_t a_end = std::min(npoints, (blk + 1) * kBlock);
        for (std::uint32_t a = blk * kBlock; a < a_end; ++a) {
            if (a % opt.entry_stride != 0) continue;
            if (chain) tracer.trace_entry(*chain, a, opt.keep_hits, s, cnt);
            else tracer.trace_entry(parts, a, opt.keep_hits, s, cnt);
        }
        if (keep_raw) block_hits[blk] = s.raw.end_block();
        if (keep_points) block_points[blk] = s.points.end_block();
        block_counts[blk] = cnt;
    }, deal_opt);
    bar.finish();

    RasterizeResult res;
    for (Scratch& s : scratch) {
        for (auto& b : s.raw.buffers()) res.raw.storage.push_back(std::move(b));
        for (auto& b : s.points.buffers()) res.points.storage.push_back(std::move(b));
    }
    for (const dist::Chunk& c : deal.chunks)
        for (std::uint32_t blk = c.begin; blk != c.end; ++blk) {
            res.pairs_traced_here += block_counts[blk].traced;
            res.hits_here += block_counts[blk].hits;
        }
    // Rank 0 gets the other ranks' blocks; theirs keep only what they counted themselves.
    if (deal_opt.across_ranks) {
        gather_blocks(deal, keep_raw, block_counts, block_hits, res.raw.storage);
        dist::mark(dist::Step::kGathered);
    }
    res.pairs_eq2 = tracer.grid().pairs_eq2();
    for (const Counts& c : block_counts) {
        res.pairs_enumerated += c.enumerated;
        res.pairs_traced += c.traced;
        res.hits += c.hits;
        res.hits_counted += c.counted;
        res.tests += c.tests;
    }
    if (keep_raw && (!deal_opt.across_ranks || dist::is_root())) res.raw.chunks = std::move(block_hits);
    else res.raw = {};
    if (keep_points) res.points.chunks = std::move(block_points);
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return res;
}

}  // namespace lat
