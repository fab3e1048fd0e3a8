#include "lattice/encodings/learned/learned_table.h"

#include <cmath>
#include <stdexcept>

#include "lattice/encodings/learned/learned_payload.h"
#include "lattice/octahedral.h"

namespace lat {

LearnedTable::LearnedTable(const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
                           const TableContext& ctx)
    : grid_({1, 1, 1}), entries_(entries), size_(size) {
    using namespace learned;
    if (size < kHeaderWords * 8 || size % 8 != 0)
        throw std::runtime_error("learned: payload too small");
    if (reinterpret_cast<std::uintptr_t>(payload) % 8 != 0)
        throw std::runtime_error("learned: payload not 8-byte aligned");
    const auto* words = reinterpret_cast<const std::uint64_t*>(payload);
    if (words[0] != (kMagic | (std::uint64_t{kVersion} << 32)))
        throw std::runtime_error("learned: wrong magic number or version");
    const Header h = decode_header(words);
    if (h.cells != ctx.cells) throw std::runtime_error("learned: payload is for other cells");
    for (const int c : h.cells)
        if (c < 1) throw std::runtime_error("learned: bad cells");
    const FieldShape& f = h.field;
    if (f.dist_bits < 2 || f.dist_bits > 24 || f.normal_bits < 2 || f.normal_bits > 16 ||
        h.ex_t < 1 || h.ex_t > 32 || h.ex_n < 2 || h.ex_n > 16)
        throw std::runtime_error("learned: bad field widths");
    if (!(std::isfinite(f.g) && f.g > 0 && std::isfinite(f.dmax) && f.dmax > 0))
        throw std::runtime_error("learned: bad node spacing");
    // The grid must be the one the build lays over these cells: that also keeps every
    // coordinate a lookup computes finite.
    for (std::size_t ax = 0; ax < 3; ++ax)
        if (f.nodes[ax] < 2 || double(f.nodes[ax]) != std::ceil(h.cells[ax] / f.g - 1e-9) + 1)
            throw std::runtime_error("learned: node grid does not fit the cells");
    grid_ = BoundaryGrid(h.cells);
    // Counts are bounded before sizes are multiplied, so nothing below can overflow.
    const std::uint64_t universe = std::uint64_t(grid_.count()) * grid_.count();
    constexpr std::uint64_t kLimit = std::uint64_t{1} << 48;
    if (f.brick_count() >= kLimit || h.dense > f.brick_count() || h.hits > universe ||
        h.corrections > universe)
        throw std::runtime_error("learned: bad counts");
    const Sections s = sections(h, universe);
    if (s.total() != size / 8)
        throw std::runtime_error("learned: payload size does not match its header");
    const std::uint64_t* p = words + kHeaderWords;
    field_ = FieldView(f, p, p + s.bitmap, p + 2 * s.bitmap, h.dense);
    p += 2 * s.bitmap + s.nodes;
    hits_ = EliasFanoView(p, s.hits);
    p += s.hits.high_words() + s.hits.low_words();
    corrections_ = EliasFanoView(p, s.corrections);
    p += s.corrections.high_words() + s.corrections.low_words();
    hit_values_ = p;
    records_ = p + s.hit_values;
    ex_t_ = h.ex_t;
    ex_n_ = h.ex_n;
}

std::uint64_t LearnedTable::bytes() const {
    return size_ + field_.index_bytes() + hits_.index_bytes() + corrections_.index_bytes();
}

bool LearnedTable::predict(std::uint32_t a, std::uint32_t b, TableHit& hit) const {
    if (a >= grid_.count() || b >= grid_.count() || a == b) return false;
    const GridPoint pa = grid_.point(a), pb = grid_.point(b);
    if (!BoundaryGrid::valid_pair(grid_.faces(pa), grid_.faces(pb))) return false;
    return field_.predict(to_vec(pa), to_vec(pb), hit);
}

bool LearnedTable::lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const {
    using namespace learned;
    if (a >= grid_.count() || b >= grid_.count() || a == b) return false;
    const GridPoint pa = grid_.point(a), pb = grid_.point(b);
    if (!BoundaryGrid::valid_pair(grid_.faces(pa), grid_.faces(pb))) return false;
    const std::uint64_t key = std::uint64_t(a) * grid_.count() + b;
    const std::uint64_t nmask = (std::uint64_t{1} << ex_n_) - 1;
    auto normal_at = [&](std::uint64_t code) {
        return oct_decode({static_cast<std::uint32_t>(code & nmask),
                           static_cast<std::uint32_t>((code >> ex_n_) & nmask)},
                          static_cast<int>(ex_n_));
    };
    std::uint64_t r;
    if (hits_.find(key, r)) {
        const unsigned w = ex_t_ + 2 * ex_n_;
        const std::uint64_t code = read_bits(hit_values_, r * w, w);
        hit.t = decode_value_t(code, ex_t_);
        hit.normal = normal_at(code >> ex_t_);
        return true;
    }
    if (!field_.predict(to_vec(pa), to_vec(pb), hit)) return false;
    if (!corrections_.find(key, r)) return true;
    const unsigned w = 2 + std::max(ex_t_, 2 * ex_n_);
    const std::uint64_t record = read_bits(records_, r * w, w);
    switch (record & 3) {
        case kMiss:
            return false;
        case kNormal:
            hit.normal = normal_at(record >> 2);
            break;
        case kT:
            hit.t = decode_value_t(record >> 2, ex_t_);
            break;
        default:
            break;  // not written by the build
    }
    return true;
}

}  // namespace lat
