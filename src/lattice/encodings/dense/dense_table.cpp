#include "lattice/encodings/dense/dense_table.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <stdexcept>

#include "geometry/lattice_source.h"
#include "geometry/shape.h"
#include "lattice/octahedral.h"

namespace lat {
namespace {

constexpr std::uint64_t kMagic = 0x31454E4553'4E4544ull;  // "DENSE1" little-endian-ish tag
constexpr double kRawNormalSlack = 0.01;  // degrees: the raw 16-bit normals' own error, bounded

struct Header {
    std::uint64_t magic;
    std::uint32_t points, t_bits;
    std::uint64_t domain, occupied;
    std::uint32_t normal_mode, normal_bits, parts, pad;
    std::uint64_t reserved[2];
};
static_assert(sizeof(Header) == 64);


struct Sections {
    std::uint64_t occ, counts, records, codes, total;  // byte offsets
};

Sections sections(const DenseTable::Layout& l) {
    Sections s{};
    const std::uint64_t nwords = words_for_bits(l.domain);
    const std::uint64_t record_bits = 2ull * (l.t_bits + l.normal_bits);
    s.occ = sizeof(Header);
    s.counts = s.occ + nwords * 8;
    s.records = s.counts + (RankIndex::count_entries(nwords) * 4 + 7) / 8 * 8;
    s.codes = s.records + (words_for_bits(l.occupied * record_bits) + 1) * 8;
    s.total = s.codes + static_cast<std::uint64_t>(l.parts) * 8;
    return s;
}

double angle_deg(Vec3 a, Vec3 b) {
    return std::acos(std::clamp(dot(a, b), -1.0, 1.0)) * 180.0 / M_PI;
}

// The largest of f(hit) over all hits (in parallel over chunks), optionally over every n-th.
template <class F>
double max_over(const RawHits& hits, F f, std::size_t stride = 1) {
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, hits.chunks.size()), 0.0,
        [&](const tbb::blocked_range<std::size_t>& r, double m) {
            for (std::size_t c = r.begin(); c != r.end(); ++c)
                for (std::size_t i = 0; i < hits.chunks[c].size(); i += stride) m = std::max(m, f(hits.chunks[c][i]));
            return m;
        },
        [](double x, double y) { return std::max(x, y); });
}

std::uint32_t quantise(double t, std::uint32_t bits) {
    const double top = double((1ull << bits) - 1);
    return static_cast<std::uint32_t>(std::lround(std::clamp(t, 0.0, 1.0) * top));
}

// The build's state, one step a method: the widths that meet the error targets, then the
// occupancy bits and their rank directory, then the payload.
class DenseBuilder {
public:
    DenseBuilder(const RawHits& raw, const TableContext& ctx, const EncodeOptions& opt)
        : raw_(raw), ctx_(ctx), opt_(opt) {
        const BoundaryGrid grid(ctx.cells);
        l_.points = grid.count();
        l_.domain = static_cast<std::uint64_t>(l_.points) * (l_.points - 1) / 2;
        point_.resize(l_.points);
        for (std::uint32_t i = 0; i < l_.points; ++i) point_[i] = to_vec(grid.point(i));
    }

    ByteBuffer build() {
        choose_widths();
        build_occupancy();
        ByteBuffer payload(sections(l_).total);
        write_sections(payload);
        write_records(payload);
        return payload;
    }

private:
    const RawHits& raw_;
    const TableContext& ctx_;
    const EncodeOptions& opt_;
    DenseTable::Layout l_;
    std::vector<Vec3> point_;
    std::map<std::pair<std::uint16_t, std::uint16_t>, std::uint32_t> code_of_;
    std::vector<std::uint32_t> codes_;  // (part, leaf) per code
    bool cheap_normals_ = true;         // every code's normal (LatticeSource::cheap_normal)
    bool use_part_ = false;
    std::vector<std::uint64_t> occ_;
    std::vector<std::uint32_t> counts_;

    static Vec3 normal_of(const RawHit& h) { return oct_decode({h.nu, h.nv}, kRawNormalBits); }
    Ray segment(const RawHit& h) const {
        return {point_[h.a] * ctx_.cell, (point_[h.b] - point_[h.a]) * ctx_.cell};
    }
    static std::uint64_t pair_of(const RawHit& h) {
        return DenseTable::pair_index(std::min(h.a, h.b), std::max(h.a, h.b));
    }

    // t: the fewest bits whose rounding keeps every point within the target.
    std::uint32_t choose_t_bits() const {
        const double lmax = max_over(raw_, [&](const RawHit& h) {
            return length(point_[h.b] - point_[h.a]) * ctx_.cell / ctx_.sigma;
        });
        std::uint32_t t_bits = 1;
        while (t_bits < 30 && 0.5 / double((1ull << t_bits) - 1) * lmax > opt_.max_point_error)
            ++t_bits;
        return t_bits;
    }

    // Part codes: the normal re-evaluated at the decoded point; t may need more bits for it.
    // Returns false when the part normals cannot meet the target, when `auto` chooses and some
    // part's normal is not cheap (LatticeSource::cheap_normal), or when there is no primitive.
    bool choose_part_codes(std::uint32_t& part_t_bits, std::uint32_t& part_bits) {
        if (ctx_.primitive == nullptr || opt_.normals == DenseNormals::kOct) return false;
        const ShapeSource primitive(*ctx_.primitive);
        for (const auto& chunk : raw_.chunks)
            for (const RawHit& h : chunk)
                if (code_of_.emplace(std::make_pair(h.part, h.leaf), std::uint32_t(code_of_.size()))
                        .second) {
                    const Crossing c = h.crossing(0);
                    codes_.push_back(c.part);
                    codes_.push_back(c.leaf);
                    cheap_normals_ = cheap_normals_ && primitive.cheap_normal(c);
                }
        if (opt_.normals == DenseNormals::kAuto && !cheap_normals_) return false;
        part_bits = 0;
        while ((1ull << part_bits) < code_of_.size()) ++part_bits;
        auto normal_at = [&](const RawHit& h, double t) {
            return normalize(ctx_.primitive->normal(segment(h), h.crossing(t)));
        };
        for (;; ++part_t_bits) {
            if (part_t_bits > 30) return false;
            const double top = double((1ull << part_t_bits) - 1);
            const double worst = max_over(raw_, [&](const RawHit& h) {
                const auto t = static_cast<double>(h.t);
                return angle_deg(normal_at(h, t), normal_at(h, quantise(t, part_t_bits) / top));
            });
            if (worst + kRawNormalSlack <= opt_.max_normal_error_deg) return true;
        }
    }

    // Octahedral normals: the fewest bits per component within the target (found on a sample,
    // then checked on every hit).
    std::uint32_t choose_oct_bits() const {
        auto worst_at = [&](std::uint32_t b, std::size_t stride) {
            return max_over(
                raw_,
                [&](const RawHit& h) {
                    const Vec3 n = normal_of(h);
                    return angle_deg(n, oct_decode(oct_encode_precise(n, int(b)), int(b)));
                },
                stride);
        };
        std::uint32_t oct_bits = 4;
        while (oct_bits < 16 && worst_at(oct_bits, 61) + kRawNormalSlack > opt_.max_normal_error_deg)
            ++oct_bits;
        while (oct_bits < 16 && worst_at(oct_bits, 1) + kRawNormalSlack > opt_.max_normal_error_deg)
            ++oct_bits;
        return oct_bits;
    }

    // Part codes or octahedral normals, whichever the options ask for; `auto`: whichever is
    // smaller, but octahedral codes where a part's normal is a quartic's gradient (a lookup
    // that decodes 2 x 8 bits or so is cheaper than that: csg of 7 tori, 400 instances on a
    // ball, 6 % faster for the same image quality).
    void choose_widths() {
        const std::uint32_t t_bits = choose_t_bits();
        std::uint32_t part_t_bits = t_bits, part_bits = 0;
        const bool part_possible = choose_part_codes(part_t_bits, part_bits);
        // Octahedral codes are only worked out when part codes are not sure to be smaller.
        std::uint32_t oct_bits = 16;
        const bool need_oct = !part_possible || opt_.normals == DenseNormals::kOct ||
                              (opt_.normals == DenseNormals::kAuto && t_bits + 2 * 4 < part_t_bits + part_bits);
        if (need_oct) oct_bits = choose_oct_bits();
        const std::uint32_t oct_record = t_bits + 2 * oct_bits, part_record = part_t_bits + part_bits;
        if (opt_.normals == DenseNormals::kPart && !part_possible)
            throw std::runtime_error("dense: part normals need the primitive");
        use_part_ = part_possible &&
                    (opt_.normals == DenseNormals::kPart || part_record < oct_record || !need_oct);
        l_.normal_mode = use_part_ ? 1 : 0;
        l_.t_bits = use_part_ ? part_t_bits : t_bits;
        l_.normal_bits = use_part_ ? part_bits : 2 * oct_bits;
        l_.parts = use_part_ ? static_cast<std::uint32_t>(code_of_.size()) : 0;
    }

    // Occupancy: a pair is stored when either direction hits.
    void build_occupancy() {
        const std::uint64_t nwords = words_for_bits(l_.domain);
        occ_.assign(nwords, 0);
        tbb::parallel_for(std::size_t{0}, raw_.chunks.size(), [&](std::size_t c) {
            for (const RawHit& h : raw_.chunks[c]) {
                const std::uint64_t i = pair_of(h);
                std::atomic_ref<std::uint64_t>(occ_[i >> 6])
                    .fetch_or(std::uint64_t{1} << (i & 63), std::memory_order_relaxed);
            }
        });
        counts_.resize(RankIndex::count_entries(nwords));
        RankIndex::build(occ_.data(), nwords, counts_.data());
        l_.occupied = counts_.back();
    }

    void write_sections(ByteBuffer& payload) const {
        const Sections sec = sections(l_);
        std::memset(payload.data(), 0, sec.total);
        const Header hdr{kMagic,        l_.points,      l_.t_bits,      l_.domain, l_.occupied,
                         l_.normal_mode, l_.normal_bits, l_.parts,       0,         {0, 0}};
        std::memcpy(payload.data(), &hdr, sizeof hdr);
        std::memcpy(payload.data() + sec.occ, occ_.data(), occ_.size() * 8);
        std::memcpy(payload.data() + sec.counts, counts_.data(), counts_.size() * 4);
        if (l_.parts) std::memcpy(payload.data() + sec.codes, codes_.data(), codes_.size() * 4);
    }

    // Records: both directions of each pair; a direction that missed only by rounding at a
    // tangency takes the other's point, reversed.
    void write_records(ByteBuffer& payload) const {
        const RankIndex rank(occ_.data(), counts_.data());
        auto* rec = reinterpret_cast<std::uint64_t*>(payload.data() + sections(l_).records);
        const std::uint32_t field = l_.t_bits + l_.normal_bits;
        std::vector<std::uint8_t> present(l_.occupied, 0);
        auto write_field = [&](std::uint64_t k, int dir, std::uint32_t tq, std::uint64_t n) {
            const std::uint64_t off = k * 2 * field + static_cast<std::uint64_t>(dir) * field;
            write_bits(rec, off, l_.t_bits, tq);
            if (l_.normal_bits) write_bits(rec, off + l_.t_bits, l_.normal_bits, n);
        };
        auto normal_field = [&](const RawHit& h) -> std::uint64_t {
            if (use_part_) return code_of_.find({h.part, h.leaf})->second;
            const Oct o = oct_encode_precise(normal_of(h), int(l_.normal_bits / 2));
            return o.u | (std::uint64_t{o.v} << (l_.normal_bits / 2));
        };
        for (const auto& chunk : raw_.chunks)
            for (const RawHit& h : chunk) {
                const std::uint64_t k = rank.rank(pair_of(h));
                const int dir = h.a < h.b ? 0 : 1;
                write_field(k, dir, quantise(static_cast<double>(h.t), l_.t_bits), normal_field(h));
                present[k] |= static_cast<std::uint8_t>(1 << dir);
            }
        // The rare lone direction (a tangency decided differently each way): copy it over.
        for (const auto& chunk : raw_.chunks)
            for (const RawHit& h : chunk) {
                const std::uint64_t k = rank.rank(pair_of(h));
                if (present[k] == 3) continue;
                write_field(k, h.a < h.b ? 1 : 0, quantise(1.0 - double(h.t), l_.t_bits),
                            normal_field(h));
            }
    }
};

}  // namespace

ByteBuffer DenseTable::build(const RawHits& raw, const TableContext& ctx, const EncodeOptions& opt) {
    return DenseBuilder(raw, ctx, opt).build();
}

DenseTable::DenseTable(const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
                       const TableContext& ctx)
    : entries_(entries), size_(size), ctx_(ctx), grid_(ctx.cells) {
    if (size < sizeof(Header)) throw std::runtime_error("dense: payload too small");
    Header h;
    std::memcpy(&h, payload, sizeof h);
    if (h.magic != kMagic) throw std::runtime_error("dense: bad payload tag");
    l_ = {h.points, h.domain, h.occupied, h.t_bits, h.normal_mode, h.normal_bits, h.parts};
    if (l_.points != grid_.count() || l_.domain != std::uint64_t(l_.points) * (l_.points - 1) / 2 ||
        l_.t_bits < 1 || l_.t_bits > 30 || l_.normal_mode > 1 || l_.normal_bits > 32 ||
        (l_.normal_mode == 0 && (l_.normal_bits % 2 || l_.normal_bits < 2)) ||
        l_.occupied > l_.domain || l_.parts > (std::uint64_t{1} << l_.normal_bits) ||
        (l_.normal_mode == 1 && l_.parts == 0))
        throw std::runtime_error("dense: inconsistent layout");
    if (l_.normal_mode == 1 && !ctx.primitive)
        throw std::runtime_error("dense: part normals need the primitive");
    const Sections sec = sections(l_);
    if (sec.total != size) throw std::runtime_error("dense: payload size does not match its layout");
    const auto* counts = reinterpret_cast<const std::uint32_t*>(payload + sec.counts);
    const std::uint64_t nwords = words_for_bits(l_.domain);
    const auto* occ = reinterpret_cast<const std::uint64_t*>(payload + sec.occ);
    if (!RankIndex::valid(occ, nwords, counts) || counts[RankIndex::count_entries(nwords) - 1] != l_.occupied)
        throw std::runtime_error("dense: rank directory does not match its occupancy bits");
    rank_ = RankIndex(occ, counts);
    records_ = reinterpret_cast<const std::uint64_t*>(payload + sec.records);
    part_codes_ = reinterpret_cast<const std::uint32_t*>(payload + sec.codes);
    // Every part code must name a surface of the primitive: lookups evaluate its normal there.
    if (l_.parts > 0 && !ctx.primitive) throw std::runtime_error("dense: part codes need the primitive");
    if (l_.parts > 0) {
        const ShapeSource primitive(*ctx.primitive);
        for (std::uint32_t i = 0; i < l_.parts; ++i)
            if (!primitive.names_surface({0.0, part_codes_[2 * i], part_codes_[2 * i + 1]}))
                throw std::runtime_error("dense: a part code names no surface of the primitive");
    }
    t_scale_ = 1.0 / double((1ull << l_.t_bits) - 1);
}

std::string DenseTable::details() const {
    const std::uint64_t nwords = words_for_bits(l_.domain);
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "%llu of %llu pairs stored; t %u bits, normals %s %u bits%s; occupancy %llu bytes, "
                  "rank directory %llu bytes, records %llu bytes",
                  static_cast<unsigned long long>(l_.occupied), static_cast<unsigned long long>(l_.domain),
                  l_.t_bits, l_.normal_mode ? "as part codes" : "octahedral", l_.normal_bits,
                  l_.normal_mode ? (" (" + std::to_string(l_.parts) + " codes)").c_str() : "",
                  static_cast<unsigned long long>(nwords * 8),
                  static_cast<unsigned long long>(RankIndex::count_entries(nwords) * 4),
                  static_cast<unsigned long long>((l_.occupied * 2 * (l_.t_bits + l_.normal_bits) + 7) / 8));
    return buf;
}

// The record of pair (a, b): its bit offset; false when the pair stores no hit.
bool DenseTable::record(std::uint32_t a, std::uint32_t b, std::uint64_t& off) const {
    if (a == b || a >= l_.points || b >= l_.points) return false;
    const std::uint32_t lo = std::min(a, b), hi = std::max(a, b);
    const std::uint64_t i = pair_index(lo, hi);
    if (!rank_.test(i)) return false;
    const std::uint32_t field = l_.t_bits + l_.normal_bits;
    off = rank_.rank(i) * 2 * field + (a < b ? 0 : field);
    return true;
}

std::uint64_t DenseTable::normal_code(std::uint64_t off) const {
    return l_.normal_bits ? read_bits(records_, off + l_.t_bits, l_.normal_bits) : 0;
}

bool DenseTable::lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const {
    std::uint64_t off = 0;
    if (!record(a, b, off)) return false;
    hit.t = double(read_bits(records_, off, l_.t_bits)) * t_scale_;
    const std::uint64_t n = normal_code(off);
    if (l_.normal_mode == 0) {
        const int bits = int(l_.normal_bits / 2);
        hit.normal = oct_decode({std::uint32_t(n & ((1u << bits) - 1)), std::uint32_t(n >> bits)}, bits);
        return true;
    }
    if (n >= l_.parts) return false;  // corrupt record
    const Vec3 pa = to_vec(grid_.point(a)), pb = to_vec(grid_.point(b));
    const Crossing c{hit.t, part_codes_[2 * n], part_codes_[2 * n + 1]};
    hit.normal = normalize(ctx_.primitive->normal({pa * ctx_.cell, (pb - pa) * ctx_.cell}, c));
    return true;
}

bool DenseTable::lookup_t(std::uint32_t a, std::uint32_t b, double& t) const {
    std::uint64_t off = 0;
    if (!record(a, b, off)) return false;
    if (l_.normal_mode != 0 && normal_code(off) >= l_.parts) return false;  // as lookup()
    t = double(read_bits(records_, off, l_.t_bits)) * t_scale_;
    return true;
}

}  // namespace lat
