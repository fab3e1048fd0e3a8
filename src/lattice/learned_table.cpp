#include "lattice/learned_table.h"

#include <cmath>
#include <stdexcept>

#include "lattice/learned_payload.h"
#include "lattice/octahedral.h"

namespace lat {
namespace {

Vec3 vec_of(const GridPoint& g) {
    return {double(g.x), double(g.y), double(g.z)};
}

}  // namespace

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
    for (const int n : f.nodes)
        if (n < 2) throw std::runtime_error("learned: bad node counts");
    grid_ = BoundaryGrid(h.cells);
    // Counts are bounded before sizes are multiplied, so nothing below can overflow.
    const std::uint64_t universe = std::uint64_t(grid_.count()) * grid_.count();
    constexpr std::uint64_t kLimit = std::uint64_t{1} << 48;
    bool bad = f.brick_count() >= kLimit || h.dense > f.brick_count();
    for (const std::uint64_t n : h.count) bad |= n > universe;
    if (bad) throw std::runtime_error("learned: bad counts");
    const Sections s = sections(h, universe);
    if (s.total() != size / 8)
        throw std::runtime_error("learned: payload size does not match its header");
    const std::uint64_t* p = words + kHeaderWords;
    field_ = FieldView(f, p, p + s.bitmap, p + 2 * s.bitmap, h.dense);
    p += 2 * s.bitmap + s.nodes;
    for (std::size_t k = 0; k < kKinds; ++k) {
        ex_[k] = EliasFanoView(p, s.keys[k]);
        p += s.keys[k].high_words() + s.keys[k].low_words();
    }
    for (std::size_t k = 0; k < kKinds; ++k) {
        values_[k] = p;
        p += s.values[k];
    }
    ex_t_ = h.ex_t;
    ex_n_ = h.ex_n;
}

std::uint64_t LearnedTable::bytes() const {
    std::uint64_t n = size_ + field_.index_bytes();
    for (const EliasFanoView& e : ex_) n += e.index_bytes();
    return n;
}

bool LearnedTable::predict(std::uint32_t a, std::uint32_t b, TableHit& hit) const {
    if (a >= grid_.count() || b >= grid_.count() || a == b) return false;
    const GridPoint pa = grid_.point(a), pb = grid_.point(b);
    if (!BoundaryGrid::valid_pair(grid_.faces(pa), grid_.faces(pb))) return false;
    return field_.predict(vec_of(pa), vec_of(pb), hit);
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
    if (ex_[kHit].find(key, r)) {
        const unsigned w = ex_t_ + 2 * ex_n_;
        const std::uint64_t code = read_bits(values_[kHit], r * w, w);
        hit.t = decode_value_t(code, ex_t_);
        hit.normal = normal_at(code >> ex_t_);
        return true;
    }
    // The other kinds only ever correct a predicted hit.
    if (!field_.predict(vec_of(pa), vec_of(pb), hit) || ex_[kMiss].find(key, r)) return false;
    if (ex_[kNormal].find(key, r))
        hit.normal = normal_at(read_bits(values_[kNormal], r * 2 * ex_n_, 2 * ex_n_));
    else if (ex_[kT].find(key, r))
        hit.t = decode_value_t(read_bits(values_[kT], r * ex_t_, ex_t_), ex_t_);
    return true;
}

}  // namespace lat
