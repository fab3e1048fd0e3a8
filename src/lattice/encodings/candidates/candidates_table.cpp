#include "lattice/encodings/candidates/candidates_table.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <unordered_map>

#include "geometry/lattice_source.h"
#include "lattice/face_cones.h"
#include "util/error.h"
#include "util/memory.h"
#include "util/progress.h"

namespace lat {
namespace {

// Payload tag "CAND3": part sets as sorted index lists of pieces (Pieces::piece_count). The
// tags before it (CAND1, CAND2) were written under another layout (Encoding::layout), so their
// files have other names in the cache and are never opened: the table is built anew.
constexpr std::uint64_t kMagic = 0x33444E4143'5441ull;

struct Header {
    std::uint64_t magic;
    std::uint32_t points, set_bits;
    std::uint64_t domain, occupied;
    std::uint32_t sets, pad;
    std::uint64_t list_total;  // entries of all part lists together
    std::uint64_t reserved[2];
};
static_assert(sizeof(Header) == 64);

struct Sections {
    std::uint64_t occ, counts, ids, sets, parts, total;
};

std::uint64_t padded8(std::uint64_t bytes) { return (bytes + 7) / 8 * 8; }

Sections sections(const Header& h) {
    Sections s{};
    const std::uint64_t nwords = words_for_bits(h.domain);
    s.occ = sizeof(Header);
    s.counts = s.occ + nwords * 8;
    s.ids = s.counts + padded8(RankIndex::count_entries(nwords) * 4);
    s.sets = s.ids + (words_for_bits(h.occupied * h.set_bits) + 1) * 8;
    s.parts = s.sets + padded8((static_cast<std::uint64_t>(h.sets) + 1) * 4);
    s.total = s.parts + padded8(h.list_total * 4);
    return s;
}

double point_segment_distance(Vec3 c, Vec3 p, Vec3 q) {
    const Vec3 d = q - p;
    const double dd = dot(d, d);
    const double t = dd > 0 ? std::clamp(dot(c - p, d) / dd, 0.0, 1.0) : 0.0;
    return length(p + d * t - c);
}

double segment_segment_distance(Vec3 p0, Vec3 p1, Vec3 q0, Vec3 q1) {
    const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
    double s = 0, t = 0;
    if (a <= 1e-300 && e <= 1e-300) return length(r);
    if (a <= 1e-300) {
        t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = dot(d1, r);
        if (e <= 1e-300) {
            s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = dot(d1, d2), den = a * e - b * b;
            s = den > 0 ? std::clamp((b * f - c * e) / den, 0.0, 1.0) : 0.0;
            t = (b * s + f) / e;
            if (t < 0) t = 0, s = std::clamp(-c / a, 0.0, 1.0);
            else if (t > 1) t = 1, s = std::clamp((b - c) / a, 0.0, 1.0);
        }
    }
    return length(p0 + d1 * s - (q0 + d2 * t));
}

// One piece of the primitive (Pieces::piece_count), in lattice units: what "within reach of a
// segment" means for it. Parts that know a capsule holding them (a chain's spheres and
// cylinders: Parts::part_capsule) are tested exactly by it; other pieces by their spheres, one at
// a time (the culling sphere that found the segment: a mesh leaf has one per triangle, and
// scanning them all for every segment would be quadratic).
struct Piece {
    enum Kind { kSphere, kCapsule, kSpheres } kind;
    Vec3 a, b;  // centre, or capsule axis
    double r;   // radius
    bool near(const PartSphere& found_by, Vec3 p, Vec3 q) const {
        if (kind == kSphere) return point_segment_distance(a, p, q) <= r + kSnapReach;
        if (kind == kCapsule) return segment_segment_distance(p, q, a, b) <= r + kSnapReach;
        return point_segment_distance(found_by.c, p, q) <= found_by.r;  // grown by the reach
    }
};

std::vector<Piece> pieces_of(const Shape& primitive, double cell) {
    std::vector<Piece> pieces;
    const ShapeSource shape(primitive);
    for (std::size_t i = 0; i < shape.piece_count(); ++i) {
        Piece p{Piece::kSpheres, {}, {}, 0};
        // The pieces are the parts where the shape is their union.
        if (Capsule c; shape.pieces_are_union() && shape.parts().part_capsule(i, c))
            p = c.a == c.b ? Piece{Piece::kSphere, c.a / cell, {}, c.r / cell}
                           : Piece{Piece::kCapsule, c.a / cell, c.b / cell, c.r / cell};
        pieces.push_back(p);
    }
    return pieces;
}

struct Scratch {
    std::vector<std::vector<std::uint32_t>> parts;  // per face point: its parts, ascending
    std::vector<std::size_t> touched;
    std::vector<std::uint32_t> self;
};

// A pair's part list, kept in its block's pool.
struct Found {
    std::uint64_t pair;
    std::uint32_t first, count;
};
struct Block {
    std::vector<Found> found;
    std::vector<std::uint32_t> pool;
    void emit(std::uint64_t pair, const std::vector<std::uint32_t>& list) {
        found.push_back({pair, static_cast<std::uint32_t>(pool.size()),
                         static_cast<std::uint32_t>(list.size())});
        pool.insert(pool.end(), list.begin(), list.end());
    }
    std::string_view list(const Found& f) const {
        return {reinterpret_cast<const char*>(pool.data() + f.first), f.count * sizeof(std::uint32_t)};
    }
};

[[noreturn]] void refuse(std::uint64_t held, std::uint64_t done, std::uint32_t points,
                         std::size_t budget) {
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "the candidates table would need more than the %s of memory it may use: its "
                  "part lists took %s for %llu of %u boundary points (they grow with the parts "
                  "near each pair); use a coarser lattice or another encoding",
                  human_bytes(double(budget)).c_str(), human_bytes(double(held)).c_str(),
                  static_cast<unsigned long long>(done), points);
    throw InputError(buf);
}

// What the rasterizer does for hits, for reach: for an entry point a, the pairs (a, b > a, and
// a with itself) and the parts within kSnapReach of the segment a b.
class CandidateFinder {
public:
    CandidateFinder(const TableContext& ctx, const BoundaryGrid& grid)
        : grid_(grid), pieces_(pieces_of(*ctx.primitive, ctx.cell)) {
        const Vec3 cells{double(ctx.cells[0]), double(ctx.cells[1]), double(ctx.cells[2])};
        cull_ = piece_spheres(*ctx.primitive, ctx.cell, cells, kSnapReach, 1e-9);
        for (int f = 0; f < 6; ++f) faces_[static_cast<std::size_t>(f)] = layout_face(grid, f);
    }

    void entry(std::uint32_t a, Scratch& s, Block& out) const {
        const GridPoint ga = grid_.point(a);
        const std::uint8_t fa = grid_.faces(ga);
        const Vec3 p = to_vec(ga);
        // The pair of a point with itself: parts within reach of the point.
        std::vector<std::uint32_t>& self = s.self;
        self.clear();
        for (const PartSphere& ps : cull_)
            if ((self.empty() || self.back() != ps.part) && pieces_[ps.part].near(ps, p, p))
                self.push_back(ps.part);
        if (!self.empty()) out.emit(CandidatesTable::pair_index(a, a), self);
        for (const FaceLayout& fl : faces_) {
            if (s.parts.size() < fl.mask.size()) s.parts.resize(fl.mask.size());
            for (const PartSphere& ps : cull_) {
                for_each_exit_in_cone(p, ps, fl, [&](std::size_t k, const Vec3& q) {
                    std::vector<std::uint32_t>& l = s.parts[k];
                    if (fl.ids[k] <= a || (!l.empty() && l.back() == ps.part)) return;
                    if (!BoundaryGrid::valid_pair(fa, fl.mask[k])) return;
                    if (!pieces_[ps.part].near(ps, p, q)) return;
                    if (l.empty()) s.touched.push_back(k);
                    l.push_back(ps.part);
                });
            }
            for (const std::size_t k : s.touched) {
                out.emit(CandidatesTable::pair_index(a, fl.ids[k]), s.parts[k]);
                s.parts[k].clear();
            }
            s.touched.clear();
        }
    }

private:
    const BoundaryGrid& grid_;
    std::vector<Piece> pieces_;
    // Grouped by part in ascending order: each face point's list is then built sorted, and a
    // part already in it is its last entry.
    std::vector<PartSphere> cull_;
    std::array<FaceLayout, 6> faces_;
};

// The pairs with candidates, per block of entry points, each block's sorted by pair. The lists
// are about half of the build's peak (the distinct sets and the payload follow): past half the
// budget it stops.
std::vector<Block> find_candidates(const TableContext& ctx, const BoundaryGrid& grid, bool progress,
                                   std::size_t budget) {
    const CandidateFinder finder(ctx, grid);
    const std::uint32_t npoints = grid.count();
    constexpr std::uint32_t kBlock = 32;
    const std::uint32_t nblocks = (npoints + kBlock - 1) / kBlock;
    std::vector<Block> blocks(nblocks);
    tbb::enumerable_thread_specific<Scratch> scratch;
    std::atomic<std::uint64_t> held{0}, done{0};
    ProgressBar bar("candidates", npoints, progress);
    tbb::parallel_for(std::uint32_t{0}, nblocks, [&](std::uint32_t blk) {
        Block& out = blocks[blk];
        const std::uint32_t end = std::min(npoints, (blk + 1) * kBlock);
        for (std::uint32_t a = blk * kBlock; a < end; ++a) finder.entry(a, scratch.local(), out);
        std::sort(out.found.begin(), out.found.end(),
                  [](const Found& x, const Found& y) { return x.pair < y.pair; });
        bar.add(end - blk * kBlock);
        const std::uint64_t bytes = out.found.capacity() * sizeof(Found) + out.pool.capacity() * 4;
        const std::uint64_t total = held += bytes, finished = done += end - blk * kBlock;
        if (budget && 2 * total > budget) refuse(total, finished, npoints, budget);
    });
    bar.finish();
    return blocks;
}

}  // namespace

ByteBuffer CandidatesTable::build(const TableContext& ctx, bool progress, std::size_t memory_budget) {
    if (!ctx.primitive) throw std::runtime_error("candidates: the table needs the primitive");
    if (ShapeSource(*ctx.primitive).piece_count() > 0xFFFFFFFFull)
        throw std::runtime_error("candidates: the primitive has more than 2^32 pieces");
    const BoundaryGrid grid(ctx.cells);
    const std::vector<Block> blocks = find_candidates(ctx, grid, progress, memory_budget);

    // Distinct part lists, numbered in first-seen order (deterministic), each stored once.
    std::unordered_map<std::string_view, std::uint32_t> set_id;
    std::vector<std::uint32_t> offsets{0}, lists;
    std::uint64_t occupied = 0;
    for (const Block& block : blocks)
        for (const Found& f : block.found) {
            ++occupied;
            if (!set_id.emplace(block.list(f), static_cast<std::uint32_t>(offsets.size() - 1)).second)
                continue;
            lists.insert(lists.end(), block.pool.begin() + f.first, block.pool.begin() + f.first + f.count);
            if (lists.size() > 0xFFFFFFFFull) throw std::runtime_error("candidates: part lists too long");
            offsets.push_back(static_cast<std::uint32_t>(lists.size()));
        }
    const auto nsets = static_cast<std::uint32_t>(offsets.size() - 1);
    std::uint32_t set_bits = 0;
    while ((1ull << set_bits) < nsets) ++set_bits;
    const std::uint32_t npoints = grid.count();
    const Header h{kMagic, npoints, set_bits, static_cast<std::uint64_t>(npoints) * (npoints + 1) / 2,
                   occupied, nsets, 0, lists.size(), {0, 0}};
    const Sections sec = sections(h);
    ByteBuffer payload(sec.total);
    std::memset(payload.data(), 0, sec.total);
    auto* occ = reinterpret_cast<std::uint64_t*>(payload.data() + sec.occ);
    for (const Block& block : blocks)
        for (const Found& f : block.found) occ[f.pair >> 6] |= std::uint64_t{1} << (f.pair & 63);
    auto* counts = reinterpret_cast<std::uint32_t*>(payload.data() + sec.counts);
    const std::uint64_t nwords = words_for_bits(h.domain);
    RankIndex::build(occ, nwords, counts);
    const RankIndex rank(occ, counts);
    auto* ids = reinterpret_cast<std::uint64_t*>(payload.data() + sec.ids);
    if (set_bits)
        for (const Block& block : blocks)
            for (const Found& f : block.found)
                write_bits(ids, rank.rank(f.pair) * set_bits, set_bits, set_id.at(block.list(f)));
    std::memcpy(payload.data() + sec.sets, offsets.data(), offsets.size() * 4);
    std::memcpy(payload.data() + sec.parts, lists.data(), lists.size() * 4);
    std::memcpy(payload.data(), &h, sizeof h);
    return payload;
}

CandidatesTable::CandidatesTable(const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
                                 const TableContext& ctx)
    : entries_(entries), size_(size), ctx_(ctx), grid_(ctx.cells) {
    if (size < sizeof(Header)) throw std::runtime_error("candidates: payload too small");
    if (!ctx.primitive) throw std::runtime_error("candidates: the table needs the primitive");
    primitive_.emplace(*ctx.primitive);
    Header h;
    std::memcpy(&h, payload, sizeof h);
    if (h.magic != kMagic) throw std::runtime_error("candidates: bad payload tag");
    points_ = h.points, set_bits_ = h.set_bits, sets_ = h.sets, occupied_ = h.occupied;
    if (points_ != grid_.count() || h.domain != std::uint64_t(points_) * (points_ + 1) / 2 ||
        set_bits_ > 32 || (sets_ > 1 && (1ull << set_bits_) < sets_) || occupied_ > h.domain ||
        sets_ > occupied_ + 1 || h.list_total > 0xFFFFFFFFull)
        throw std::runtime_error("candidates: inconsistent layout");
    const Sections sec = sections(h);
    if (sec.total != size) throw std::runtime_error("candidates: payload size does not match its layout");
    const std::uint64_t nwords = words_for_bits(h.domain);
    const auto* counts = reinterpret_cast<const std::uint32_t*>(payload + sec.counts);
    const auto* occ = reinterpret_cast<const std::uint64_t*>(payload + sec.occ);
    if (!RankIndex::valid(occ, nwords, counts) || counts[RankIndex::count_entries(nwords) - 1] != occupied_)
        throw std::runtime_error("candidates: rank directory does not match its occupancy bits");
    rank_ = RankIndex(occ, counts);
    ids_ = reinterpret_cast<const std::uint64_t*>(payload + sec.ids);
    offsets_ = reinterpret_cast<const std::uint32_t*>(payload + sec.sets);
    parts_ = reinterpret_cast<const std::uint32_t*>(payload + sec.parts);
    check_lists(h.list_total);
}

// Every list lies within the index array, ascending, and names parts the primitive has.
void CandidatesTable::check_lists(std::uint64_t total) const {
    const std::uint64_t nparts = primitive_->piece_count();
    if (offsets_[0] != 0 || offsets_[sets_] != total)
        throw std::runtime_error("candidates: part list offsets do not match their count");
    for (std::uint32_t i = 0; i < sets_; ++i) {
        if (offsets_[i] > offsets_[i + 1])
            throw std::runtime_error("candidates: part list offsets out of order");
        for (std::uint32_t k = offsets_[i]; k < offsets_[i + 1]; ++k)
            if (parts_[k] >= nparts || (k > offsets_[i] && parts_[k] <= parts_[k - 1]))
                throw std::runtime_error("candidates: a part set names parts the primitive does not have");
    }
}

std::string CandidatesTable::details() const {
    char buf[200];
    std::snprintf(buf, sizeof buf, "%llu pairs with candidates, %u distinct part sets (%u bits a pair)",
                  static_cast<unsigned long long>(occupied_), sets_, set_bits_);
    return buf;
}

bool CandidatesTable::candidates(std::uint32_t a, std::uint32_t b, CandidateList& out) const {
    if (a >= points_ || b >= points_) return false;
    const std::uint64_t i = pair_index(std::min(a, b), std::max(a, b));
    if (!rank_.test(i)) return false;
    const std::uint64_t id = set_bits_ ? read_bits(ids_, rank_.rank(i) * set_bits_, set_bits_) : 0;
    if (id >= sets_) return false;  // corrupt
    out.parts = parts_ + offsets_[id];
    out.count = static_cast<int>(offsets_[id + 1] - offsets_[id]);
    return true;
}

bool CandidatesTable::lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const {
    // As rasterization answers: the candidates intersected exactly with the segment.
    CandidateList list;
    if (a == b || !candidates(a, b, list)) return false;
    const Vec3 pa = to_vec(grid_.point(a)), pb = to_vec(grid_.point(b));
    const Ray seg{pa * ctx_.cell, (pb - pa) * ctx_.cell};
    const Shape& shape = *ctx_.primitive;
    const ShapeSource& source = *primitive_;
    if (shape.inside(seg.o)) {  // a point of the closed solid on the box: the hit is the point
        hit = {0.0, normalize(shape.normal(seg, nearest_crossing(shape, seg)))};
        return true;
    }
    Crossing best{kInfinity, 0, 0};
    if (!source.pieces_are_union()) {
        shape.intersect(seg, 0.0, 1.0 + 1e-12, best);  // not a hot path: the whole primitive
    } else {
        for (int k = 0; k < list.count; ++k) {
            Crossing c;
            const double tmax = std::min(best.t, 1.0 + 1e-12);
            if (source.parts().intersect_part(list.parts[k], seg, 0.0, tmax, c)) best = c;
        }
    }
    if (best.t > 1.0) return false;
    hit = {std::min(best.t, 1.0), normalize(shape.normal(seg, best))};
    return true;
}

}  // namespace lat
