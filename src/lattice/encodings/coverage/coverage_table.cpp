#include "lattice/encodings/coverage/coverage_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "lattice/coverage.h"
#include "lattice/octahedral.h"

namespace lat {
namespace {

constexpr std::uint64_t kMagic = 0x3252'4556'4F43ull;  // "COVER2"
// The layout before (pairs indexed a * N + b, with a rank directory): refused with a word on
// what to do (the table cache never meets one: Encoding::layout is in its file names).
constexpr std::uint64_t kOldMagic = 0x3152'4556'4F43ull;  // "COVER1"
constexpr std::size_t kRecordBytes = CoverageTable::kRecordBytes;
constexpr double kTScale = 65534.0;
constexpr double kAlphaScale = 65535.0;

struct Header {
    std::uint64_t magic;
    std::uint32_t points, rays;  // boundary points; sub-rays per pair
    std::uint64_t occupied;      // records
    std::uint64_t center_hits;   // records whose own segment hits (the table's entries)
    std::uint64_t slots;         // PairIndex::slots() of the lattice
    std::uint64_t reserved[3];
};
static_assert(sizeof(Header) == 64);

std::uint64_t padded8(std::uint64_t bytes) { return (bytes + 7) / 8 * 8; }

// The payload: the header, an occupancy bit per slot, the records in slot order.
struct Sections {
    std::uint64_t nwords, occ, records, total;
};

Sections sections(std::uint64_t slots, std::uint64_t occupied) {
    Sections s{};
    s.nwords = words_for_bits(slots);
    s.occ = sizeof(Header);
    s.records = s.occ + s.nwords * 8;
    s.total = s.records + padded8(occupied * kRecordBytes);
    return s;
}

std::uint16_t field(const std::uint8_t* rec, int f) {
    std::uint16_t v;
    std::memcpy(&v, rec + 2 * f, 2);
    return v;
}

std::uint16_t quantise_t(double t) {
    return static_cast<std::uint16_t>(std::lround(std::clamp(t, 0.0, 1.0) * kTScale));
}

// One record in the making: the pair's own hit and its coverage, merged by pair.
struct Entry {
    std::uint64_t pair;
    std::array<std::uint16_t, CoverageTable::kFields> f;
};

}  // namespace

ByteBuffer CoverageTable::build(const RawHits& hits, const TableContext& ctx, const EncodeOptions&) {
    const BoundaryGrid grid(ctx.cells);
    const std::uint64_t n = grid.count();
    std::vector<Entry> entries;
    entries.reserve(hits.size());
    for (const auto& chunk : hits.chunks)
        for (const RawHit& h : chunk)
            entries.push_back({h.a * n + h.b, {quantise_t(h.t), h.nu, h.nv, 0, 0, 0, 0}});
    std::sort(entries.begin(), entries.end(),
              [](const Entry& x, const Entry& y) { return x.pair < y.pair; });
    const std::size_t centers = entries.size();
    // Coverage samples come sorted by pair: merge them into the hits, adding the pairs whose
    // own segment misses.
    std::size_t next = 0;
    for (const CoverageSample& c : rasterize_coverage(ctx, false)) {
        const std::uint64_t pair = c.a * n + c.b;
        while (next < centers && entries[next].pair < pair) ++next;
        Entry* e = nullptr;
        if (next < centers && entries[next].pair == pair) {
            e = &entries[next];
        } else {
            entries.push_back({pair, {kNoHit, 0, 0, 0, 0, 0, 0}});
            e = &entries.back();
        }
        e->f[kMeanT] = quantise_t(c.t);
        e->f[kMeanNu] = c.nu, e->f[kMeanNv] = c.nv;
        e->f[kAlpha] = static_cast<std::uint16_t>(std::lround(double(c.alpha) * kAlphaScale));
    }
    // Filed by slot; a stored pair is a valid one (rasterizing skips the others).
    const PairIndex index(ctx.cells);
    for (Entry& e : entries) {
        e.pair = index.slot(static_cast<std::uint32_t>(e.pair / n), static_cast<std::uint32_t>(e.pair % n));
        if (e.pair == PairIndex::kNone) throw std::logic_error("coverage: a stored pair is not valid");
    }
    std::sort(entries.begin(), entries.end(), [](const Entry& x, const Entry& y) { return x.pair < y.pair; });

    const Sections s = sections(index.slots(), entries.size());
    ByteBuffer out(s.total);
    std::memset(out.data(), 0, s.total);
    const Header h{kMagic, static_cast<std::uint32_t>(n), kCoverageRays, entries.size(), centers,
                   index.slots(), {}};
    std::memcpy(out.data(), &h, sizeof h);
    auto* occ = reinterpret_cast<std::uint64_t*>(out.data() + s.occ);
    std::uint8_t* rec = out.data() + s.records;
    for (const Entry& e : entries) {
        occ[e.pair >> 6] |= std::uint64_t{1} << (e.pair & 63);
        std::memcpy(rec, e.f.data(), kRecordBytes);
        rec += kRecordBytes;
    }
    return out;
}

CoverageTable::CoverageTable(const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
                             const TableContext& ctx)
    : index_(ctx.cells), entries_(entries), size_(size) {
    auto fail = [](const char* why) {
        throw std::runtime_error(std::string("coverage payload: ") + why);
    };
    if (size < sizeof(Header)) fail("shorter than its header");
    Header h;
    std::memcpy(&h, payload, sizeof h);
    if (h.magic == kOldMagic) fail("an older layout (COVER1); rebuild the table");
    if (h.magic != kMagic) fail("bad tag");
    if (h.points != index_.grid().count()) fail("boundary point count differs from the lattice's");
    if (h.slots != index_.slots()) fail("slot count differs from the lattice's");
    if (h.rays != kCoverageRays) fail("sampled with a different number of sub-rays");
    if (h.center_hits != entries || h.occupied < entries || h.occupied > (std::uint64_t{1} << 40))
        fail("record counts inconsistent with the header");
    const Sections s = sections(h.slots, h.occupied);
    if (s.total != size) fail("size does not match its counts");
    const auto* occ = reinterpret_cast<const std::uint64_t*>(payload + s.occ);
    build_lines(occ);
    if (lines_[s.nwords / PairIndex::kTileWords].base != h.occupied)
        fail("occupancy does not match the record count");
    // A set bit where no pair is filed would be a record no lookup reaches.
    for (std::uint64_t w = 0; w < s.nwords; ++w) {
        if (!occ[w] || (w % PairIndex::kTileWords == 0 && index_.plain_tile(w / PairIndex::kTileWords)))
            continue;
        std::uint32_t a = 0, b = 0;
        for (std::uint64_t bits = occ[w]; bits; bits &= bits - 1)
            if (!index_.pair_at(w * 64 + static_cast<unsigned>(std::countr_zero(bits)), a, b))
                fail("occupancy bits where no pair is filed");
    }
    occupied_ = h.occupied;
    records_ = payload + s.records;
    std::uint64_t centers = 0;
    for (std::uint64_t i = 0; i < occupied_; ++i) {
        const std::uint8_t* r = records_ + i * kRecordBytes;
        const std::uint16_t t = field(r, kT), alpha = field(r, kAlpha);
        if ((t != kNoHit && t > kTScale) || field(r, kMeanT) > kTScale || (t == kNoHit && alpha == 0))
            fail("a record out of range");
        centers += t != kNoHit;
        partial_ += alpha > 0 && alpha < kAlphaScale;
        alpha_sum_ += alpha / kAlphaScale;
    }
    if (centers != entries) fail("hit count does not match the header");
}

// One line per tile and a last one past them, whose base is the count of all set bits.
void CoverageTable::build_lines(const std::uint64_t* occ) {
    const std::uint64_t tiles = index_.slots() / PairIndex::kTileSlots;
    lines_ = std::make_unique<RankLine[]>(tiles + 1);
    size_ += (tiles + 1) * sizeof(RankLine);
    std::uint64_t below = 0;
    for (std::uint64_t t = 0; t <= tiles; ++t) {
        RankLine& l = lines_[t];
        l.base = below;
        for (int k = 0; k < PairIndex::kTileWords; ++k) {
            l.bits[k] = t < tiles ? occ[t * PairIndex::kTileWords + static_cast<std::uint64_t>(k)] : 0;
            below += static_cast<std::uint64_t>(std::popcount(l.bits[k]));
        }
    }
}

const std::uint8_t* CoverageTable::record(std::uint32_t a, std::uint32_t b) const {
    const std::uint64_t i = index_.slot(a, b);
    return i == PairIndex::kNone ? nullptr : record_at(i);
}

bool CoverageTable::lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const {
    const std::uint8_t* r = record(a, b);
    if (!r || field(r, kT) == kNoHit) return false;
    hit.t = field(r, kT) / kTScale;
    hit.normal = oct_decode({field(r, kNu), field(r, kNv)}, kRawNormalBits);
    return true;
}

void CoverageTable::decode(const std::uint8_t* r, CoverageHit& hit, bool normal) {
    hit.alpha = field(r, kAlpha) / kAlphaScale;
    hit.t = field(r, kMeanT) / kTScale;
    if (normal) hit.normal = oct_decode({field(r, kMeanNu), field(r, kMeanNv)}, kRawNormalBits);
}

bool CoverageTable::coverage(std::uint32_t a, std::uint32_t b, CoverageHit& hit) const {
    const std::uint8_t* r = record(a, b);
    if (!r || field(r, kAlpha) == 0) return false;
    decode(r, hit, true);
    return true;
}

void CoverageTable::coverage_many(const std::uint32_t* a, const std::uint32_t* b, int n,
                                  CoverageHit* out, bool* found, bool normals) const {
    // Three passes, each prefetching what the next reads, so that the cache misses of the pairs
    // (rank line, record: two a pair in a table of hundreds of MB) overlap instead of following
    // one another.
    constexpr int kMax = 16;
    std::uint64_t idx[kMax];
    const std::uint8_t* rec[kMax];
    for (int base = 0; base < n; base += kMax) {
        const int m = std::min(kMax, n - base);
        for (int i = 0; i < m; ++i) {
            idx[i] = index_.slot(a[base + i], b[base + i]);
            if (idx[i] != PairIndex::kNone) __builtin_prefetch(line_of(idx[i]));
        }
        for (int i = 0; i < m; ++i) {
            rec[i] = idx[i] != PairIndex::kNone ? record_at(idx[i]) : nullptr;
            if (rec[i]) __builtin_prefetch(rec[i]);
        }
        for (int i = 0; i < m; ++i) {
            found[base + i] = rec[i] && field(rec[i], kAlpha) != 0;
            if (found[base + i]) decode(rec[i], out[base + i], normals);
        }
    }
}

void CoverageTable::prefetch_coverage(const std::uint32_t* a, const std::uint32_t* b, int n) const {
    for (int i = 0; i < n; ++i) {
        const std::uint64_t idx = index_.slot(a[i], b[i]);
        if (idx != PairIndex::kNone) __builtin_prefetch(line_of(idx));
    }
}

std::string CoverageTable::details() const {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "%llu records, %d sub-rays a pair; coverage: %llu pairs partly covered "
                  "(0 < alpha < 1), %.0f pairs' worth in all, %.3f records per hit",
                  static_cast<unsigned long long>(occupied_), kCoverageRays,
                  static_cast<unsigned long long>(partial_), alpha_sum_,
                  entries_ ? double(occupied_) / double(entries_) : 0.0);
    return buf;
}

}  // namespace lat
