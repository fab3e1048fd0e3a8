#include "lattice/encodings/coverage/coverage_table.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "lattice/bits/bit_array.h"
#include "lattice/coverage.h"
#include "lattice/octahedral.h"

namespace lat {
namespace {

constexpr std::uint64_t kMagic = 0x3452'4556'4F43ull;  // "COVER4"
// The layouts before, refused with a word on what to do (the table cache never meets one:
// Encoding::layout is in its file names): "COVER1", pairs indexed a * N + b with a rank
// directory; "COVER2", coverage records of four 16-bit fields; "COVER3", 32-bit records
// without the normals' spread. Their tags differ from this one in the last character alone.
constexpr std::uint64_t kOldMagics[] = {0x3152'4556'4F43ull, 0x3252'4556'4F43ull, 0x3352'4556'4F43ull};
constexpr std::size_t kHitBytes = CoverageTable::kHitBytes, kCoverBytes = CoverageTable::kCoverBytes;
constexpr int kGroupSlots = CoverageTable::kGroupSlots;
constexpr double kTScale = 65534.0;
constexpr std::uint32_t kAlphaTop = (1u << CoverageTable::kAlphaBits) - 1;
constexpr std::uint32_t kMeanTTop = (1u << CoverageTable::kMeanTBits) - 1;
constexpr std::uint32_t kMeanNormalTop = (1u << CoverageTable::kMeanNormalBits) - 1;
constexpr int kMeanTShift = CoverageTable::kAlphaBits;
constexpr int kNuShift = kMeanTShift + CoverageTable::kMeanTBits;
constexpr int kNvShift = kNuShift + CoverageTable::kMeanNormalBits;
constexpr int kSpreadShift = kNvShift + CoverageTable::kMeanNormalBits;
constexpr std::uint32_t kSpreadTop = (1u << CoverageTable::kSpreadBits) - 1;
// The mean normal's length for each spread code k: sqrt(1 - (k / kSpreadTop)^2).
const std::array<double, kSpreadTop + 1> kSpreadLength = [] {
    std::array<double, kSpreadTop + 1> len{};
    for (std::uint32_t k = 0; k <= kSpreadTop; ++k) {
        const double s = k / double(kSpreadTop);
        len[k] = std::sqrt(1 - s * s);
    }
    return len;
}();

struct Header {
    std::uint64_t magic;
    std::uint32_t points, rays;  // boundary points; sub-rays per pair
    std::uint64_t occupied;      // stored pairs
    std::uint64_t center_hits;   // those whose own segment hits (the table's entries)
    std::uint64_t slots;         // PairIndex::slots() of the lattice
    std::uint64_t groups;        // groups of 16 slots kept
    std::uint64_t reserved[2];
};
static_assert(sizeof(Header) == 64);

std::uint64_t padded(std::uint64_t bytes, std::uint64_t to) { return (bytes + to - 1) / to * to; }

// The payload: the header, a bit per group of 16 slots (kept or not), the kept groups'
// coverage records, then their hit records (16 a group, in slot order). The coverage records
// start on a cache line (a payload starts 128 bytes into its file, read or mapped at a page),
// so that a group's are two whole lines.
struct Sections {
    std::uint64_t nwords, kept, covers, hits, total;
};

Sections sections(std::uint64_t slots, std::uint64_t groups) {
    Sections s{};
    s.nwords = words_for_bits(slots / kGroupSlots);
    s.kept = sizeof(Header);
    s.covers = padded(s.kept + s.nwords * 8, 64);
    s.hits = s.covers + groups * kGroupSlots * kCoverBytes;
    s.total = padded(s.hits + groups * kGroupSlots * kHitBytes, 8);
    return s;
}

std::uint16_t field(const std::uint8_t* rec, int f) {
    std::uint16_t v;
    std::memcpy(&v, rec + 2 * f, 2);
    return v;
}

std::uint32_t cover_of(const std::uint8_t* rec) {
    std::uint32_t v;
    std::memcpy(&v, rec, 4);
    return v;
}

std::uint16_t quantise_t(double t) {
    return static_cast<std::uint16_t>(std::lround(std::clamp(t, 0.0, 1.0) * kTScale));
}

// One record in the making: the pair's own hit and its coverage, merged by pair.
struct Entry {
    std::uint64_t pair;
    std::array<std::uint16_t, CoverageTable::kFields> f;
    std::uint32_t cover;
};

// The records of a table: the rasterized hits and the coverage samples merged by pair, filed
// by slot (a stored pair is a valid one: rasterizing skips the others), in slot order.
std::vector<Entry> entries_by_slot(const RawHits& hits, const TableContext& ctx,
                                   const PairIndex& index, bool progress) {
    constexpr std::uint16_t kNoHit = CoverageTable::kNoHit;
    const std::uint64_t n = index.grid().count();
    std::vector<Entry> entries;
    entries.reserve(hits.size());
    for (const auto& chunk : hits.chunks)
        for (const RawHit& h : chunk) {
            const std::uint16_t t = quantise_t(static_cast<double>(h.t));
            entries.push_back({h.a * n + h.b, {t, h.nu, h.nv}, 0});
        }
    const auto by_pair = [](const Entry& x, const Entry& y) { return x.pair < y.pair; };
    std::sort(entries.begin(), entries.end(), by_pair);
    const std::size_t centers = entries.size();
    // Coverage samples come sorted by pair: merge them into the hits, adding the pairs whose
    // own segment misses.
    std::size_t next = 0;
    for (const CoverageSample& c : rasterize_coverage(ctx, progress)) {
        const std::uint64_t pair = c.a * n + c.b;
        while (next < centers && entries[next].pair < pair) ++next;
        Entry* e = nullptr;
        if (next < centers && entries[next].pair == pair) {
            e = &entries[next];
        } else {
            entries.push_back({pair, {kNoHit, 0, 0}, 0});
            e = &entries.back();
        }
        e->cover = CoverageTable::pack_cover(c);
    }
    for (Entry& e : entries) {
        e.pair = index.slot(static_cast<std::uint32_t>(e.pair / n), static_cast<std::uint32_t>(e.pair % n));
        if (e.pair == PairIndex::kNone) throw std::logic_error("coverage: a stored pair is not valid");
    }
    std::sort(entries.begin(), entries.end(), by_pair);
    return entries;
}

}  // namespace

ByteBuffer CoverageTable::build(const RawHits& hits, const TableContext& ctx, const EncodeOptions& opt) {
    const PairIndex index(ctx.cells);
    const std::vector<Entry> entries = entries_by_slot(hits, ctx, index, opt.progress);
    std::uint64_t groups = 0, centers = 0;
    for (std::size_t i = 0; i < entries.size(); ++i) {
        groups += i == 0 || entries[i].pair / kGroupSlots != entries[i - 1].pair / kGroupSlots;
        centers += entries[i].f[kT] != kNoHit;
    }
    const Sections s = sections(index.slots(), groups);
    ByteBuffer out(s.total);
    std::memset(out.data(), 0, s.total);
    const Header h{kMagic, index.grid().count(), static_cast<std::uint32_t>(ctx.coverage_rays),
                   entries.size(), centers,
                   index.slots(), groups, {}};
    std::memcpy(out.data(), &h, sizeof h);
    auto* kept = reinterpret_cast<std::uint64_t*>(out.data() + s.kept);
    std::uint64_t k = 0;  // the group being written, among the kept ones
    for (std::size_t i = 0; i < entries.size(); ++i) {
        const std::uint64_t g = entries[i].pair / kGroupSlots;
        const bool first = i == 0 || g != entries[i - 1].pair / kGroupSlots;
        if (first && i > 0) ++k;
        std::uint8_t* hit = out.data() + s.hits + k * kGroupSlots * kHitBytes;
        if (first) {
            kept[g / 64] |= std::uint64_t{1} << (g % 64);
            // The empty slots' hit records say no hit (their coverage records, all 0, no alpha).
            for (int j = 0; j < kGroupSlots; ++j) std::memcpy(hit + j * kHitBytes, &kNoHit, 2);
        }
        const std::uint64_t j = entries[i].pair % kGroupSlots;
        std::memcpy(hit + j * kHitBytes, entries[i].f.data(), kHitBytes);
        std::memcpy(out.data() + s.covers + (k * kGroupSlots + j) * kCoverBytes, &entries[i].cover,
                    kCoverBytes);
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
    for (const std::uint64_t old : kOldMagics)
        if (h.magic == old)
            throw std::runtime_error(std::string("coverage payload: an older layout (COVER") +
                                     static_cast<char>(old >> 40) + "); rebuild the table");
    if (h.magic != kMagic) fail("bad tag");
    if (h.points != index_.grid().count()) fail("boundary point count differs from the lattice's");
    if (h.slots != index_.slots()) fail("slot count differs from the lattice's");
    if (h.rays > 1024 || !valid_coverage_rays(static_cast<int>(h.rays)))
        fail("its count of sub-rays a pair is not a power of two up to 1024");
    if (ctx.coverage_rays != kAnyCoverageRays && h.rays != static_cast<std::uint32_t>(ctx.coverage_rays))
        throw std::runtime_error("coverage payload: sampled with " + std::to_string(h.rays) +
                                 " sub-rays a pair where " + std::to_string(ctx.coverage_rays) +
                                 " are asked for; rebuild it");
    rays_ = static_cast<int>(h.rays);
    if (h.center_hits != entries || h.occupied < entries || h.occupied > (std::uint64_t{1} << 40))
        fail("record counts inconsistent with the header");
    if (h.groups > h.occupied) fail("more kept groups than stored pairs");
    const Sections s = sections(h.slots, h.groups);
    if (s.total != size) fail("size does not match its counts");
    occupied_ = h.occupied;
    kept_groups_ = h.groups;
    const auto* kept = reinterpret_cast<const std::uint64_t*>(payload + s.kept);
    if (build_lines(kept, s.nwords) != h.groups) fail("kept groups do not match the header's count");
    // Bits past the last group would keep groups of no slot.
    if ((h.slots / kGroupSlots) % 64 && kept[s.nwords - 1] >> ((h.slots / kGroupSlots) % 64))
        fail("kept-group bits past the last group");
    covers_ = payload + s.covers;
    hits_ = payload + s.hits;
    check_records(kept);
}

// Returns the set bits in all.
std::uint64_t CoverageTable::build_lines(const std::uint64_t* kept, std::uint64_t nwords) {
    // A word holds 4 tiles' bits (check_records reads them so too).
    static_assert(64 % kTileGroups == 0);
    constexpr std::uint64_t kWordTiles = 64 / kTileGroups;
    const std::uint64_t tiles = nwords * kWordTiles;
    const std::uint64_t nlines = (tiles + RankLine::kTiles - 1) / RankLine::kTiles;
    lines_ = std::make_unique<RankLine[]>(nlines);  // zeroed: tiles past the last keep none
    size_ += nlines * sizeof(RankLine);
    std::uint64_t below = 0;
    for (std::uint64_t t = 0; t < tiles; ++t) {
        RankLine& l = lines_[t / RankLine::kTiles];
        const auto i = static_cast<unsigned>(t % RankLine::kTiles);
        if (i == 0) l.base = below;
        const auto bits = static_cast<std::uint16_t>(kept[t / kWordTiles] >> (t % kWordTiles * kTileGroups));
        l.kept[i] = bits;
        l.before[i] = static_cast<std::uint8_t>(below - l.base);
        below += static_cast<std::uint64_t>(std::popcount(bits));
    }
    return below;
}

// Each slot of a kept group stored or empty; stored pairs' records in range, on a slot where a
// pair is filed, as many as the header says; no kept group empty.
void CoverageTable::check_records(const std::uint64_t* kept) {
    auto fail = [](const char* why) {
        throw std::runtime_error(std::string("coverage payload: ") + why);
    };
    static_assert(PairIndex::kTileSlots == 16 * kGroupSlots);  // a tile's bits: 16 of a word
    const std::uint64_t tiles = index_.slots() / PairIndex::kTileSlots;
    std::uint64_t count = 0, centers = 0, group = 0;
    for (std::uint64_t t = 0; t < tiles; ++t) {
        const auto in_tile = static_cast<unsigned>((kept[t / 4] >> (t % 4 * 16)) & 0xFFFF);
        if (!in_tile) continue;
        std::array<std::uint64_t, PairIndex::kTileSlots / 64> stored{};
        for (unsigned g = 0; g < 16; ++g) {
            if (!((in_tile >> g) & 1u)) continue;
            int in_group = 0;
            for (unsigned j = 0; j < kGroupSlots; ++j) {
                const Place p{group, j, true};
                const std::uint8_t *c = cover_at(p), *h = hit_at(p);
                const std::uint16_t tt = field(h, kT);
                const std::uint32_t cover = cover_of(c), alpha = cover & kAlphaTop;
                // (Every value of a coverage record's fields is in range.)
                if (alpha == 0 && cover != 0) fail("a coverage record without alpha not empty");
                if (tt == kNoHit && alpha == 0) {
                    if (field(h, kNu) || field(h, kNv)) fail("an empty slot's records not empty");
                    continue;
                }
                if (tt != kNoHit && tt > kTScale) fail("a record out of range");
                const unsigned inner = g * kGroupSlots + j;
                stored[inner / 64] |= std::uint64_t{1} << (inner % 64);
                ++in_group;
                centers += tt != kNoHit;
                partial_ += alpha > 0 && alpha < kAlphaTop;
                alpha_sum_ += double(alpha) / kAlphaTop;
            }
            if (!in_group) fail("a kept group without records");
            count += static_cast<unsigned>(in_group);
            ++group;
        }
        if (!index_.filed(t, stored)) fail("a record where no pair is filed");
    }
    if (count != occupied_) fail("records do not match the header's count");
    if (centers != entries_) fail("hit count does not match the header");
}

CoverageTable::Place CoverageTable::place(std::uint32_t a, std::uint32_t b) const {
    const std::uint64_t s = index_.slot(a, b);
    return s == PairIndex::kNone ? Place{0, 0, false} : place_of(s);
}

bool CoverageTable::lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const {
    const Place p = place(a, b);
    if (!p.kept) return false;
    const std::uint8_t* h = hit_at(p);
    if (field(h, kT) == kNoHit) return false;
    hit.t = field(h, kT) / kTScale;
    hit.normal = oct_decode({field(h, kNu), field(h, kNv)}, kRawNormalBits);
    return true;
}

std::uint32_t CoverageTable::pack_cover(const CoverageSample& c) {
    assert(c.alpha > 0);
    // At least one step: a sample kept has alpha >= kCoverageMinAlpha, several steps.
    const auto alpha = std::max<std::uint32_t>(
        1, static_cast<std::uint32_t>(std::lround(std::clamp(double(c.alpha), 0.0, 1.0) * kAlphaTop)));
    const auto t = static_cast<std::uint32_t>(std::lround(std::clamp(double(c.t), 0.0, 1.0) * kMeanTTop));
    const Oct o = oct_encode_precise(oct_decode({c.nu, c.nv}, kRawNormalBits), kMeanNormalBits);
    const auto spread = static_cast<std::uint32_t>(std::lround(c.spread / 255.0 * kSpreadTop));
    return alpha | t << kMeanTShift | o.u << kNuShift | o.v << kNvShift | spread << kSpreadShift;
}

void CoverageTable::unpack_cover(std::uint32_t cover, CoverageHit& hit, bool normal) {
    hit.alpha = (cover & kAlphaTop) / double(kAlphaTop);
    hit.t = (cover >> kMeanTShift & kMeanTTop) / double(kMeanTTop);
    if (!normal) return;
    hit.normal = kSpreadLength[cover >> kSpreadShift & kSpreadTop] *
                 oct_decode({cover >> kNuShift & kMeanNormalTop, cover >> kNvShift & kMeanNormalTop},
                            kMeanNormalBits);
}

bool CoverageTable::coverage(std::uint32_t a, std::uint32_t b, CoverageHit& hit) const {
    const Place p = place(a, b);
    if (!p.kept) return false;
    const std::uint32_t cover = cover_of(cover_at(p));
    if ((cover & kAlphaTop) == 0) return false;
    unpack_cover(cover, hit, true);
    return true;
}

void CoverageTable::locate_coverage(const std::uint32_t* a, const std::uint32_t* b, int n,
                                    std::uint64_t* ref) const {
    for (int i = 0; i < n; ++i) ref[i] = locate(index_.slot(a[i], b[i]));
}

void CoverageTable::coverage_at(const std::uint64_t* ref, int n, CoverageHit* out, bool* found,
                                bool normals) const {
    for (int i = 0; i < n; ++i) {
        const auto* c = reinterpret_cast<const std::uint8_t*>(static_cast<std::uintptr_t>(ref[i]));
        const std::uint32_t cover = c ? cover_of(c) : 0;
        found[i] = (cover & kAlphaTop) != 0;
        if (found[i]) unpack_cover(cover, out[i], normals);
    }
}

std::string CoverageTable::details() const {
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "%llu records (in %llu groups of 16 slots), %d sub-rays a pair; coverage: %llu "
                  "pairs partly covered (0 < alpha < 1), %.0f pairs' worth in all, %.3f records "
                  "per hit",
                  static_cast<unsigned long long>(occupied_),
                  static_cast<unsigned long long>(kept_groups_), rays_,
                  static_cast<unsigned long long>(partial_), alpha_sum_,
                  entries_ ? double(occupied_) / double(entries_) : 0.0);
    return buf;
}

}  // namespace lat
