#include "lattice/learned_table.h"

#include <cstring>
#include <stdexcept>

#include "lattice/learned_payload.h"

namespace lat {

LearnedLayout::LearnedLayout(std::array<int, 3> cells, int step) : step_(step) {
    for (int f = 0; f < 6; ++f) {
        Face& F = faces_[static_cast<std::size_t>(f)];
        const int axis = BoundaryGrid::face_axis(f);
        F.ua = (axis + 1) % 3;
        F.va = (axis + 2) % 3;
        F.nu = cells[static_cast<std::size_t>(F.ua)] + 1;
        F.nv = cells[static_cast<std::size_t>(F.va)] + 1;
        F.cu = (F.nu - 2) / step + 2;  // nodes 0, s, ..., and nu - 1 when it is not one of them
        F.cv = (F.nv - 2) / step + 2;
    }
    for (int fa = 0; fa < 6; ++fa)
        for (int fb = 0; fb < 6; ++fb) {
            if (fa == fb) continue;
            sample_base_[idx(fa, fb)] = samples_;
            key_base_[idx(fa, fb)] = keys_;
            samples_ += face(fa).nodes() * face(fb).nodes();
            keys_ += face(fa).points() * face(fb).points();
        }
}

void LearnedLayout::owner(std::uint8_t ma, std::uint8_t mb, int& fa, int& fb) {
    fa = __builtin_ctz(ma);
    fb = __builtin_ctz(mb);
    if (fa != fb) return;
    const unsigned rest_b = mb & ~(1u << fb);
    if (rest_b) fb = __builtin_ctz(rest_b);
    else fa = __builtin_ctz(ma & ~(1u << fa));
}

void learned_weights(const AxisCell& au, const AxisCell& av, const AxisCell& bu,
                     const AxisCell& bv, double w[16]) {
    const double a[4] = {(1 - au.w1) * (1 - av.w1), au.w1 * (1 - av.w1), (1 - au.w1) * av.w1,
                         au.w1 * av.w1};
    const double b[4] = {(1 - bu.w1) * (1 - bv.w1), bu.w1 * (1 - bv.w1), (1 - bu.w1) * bv.w1,
                         bu.w1 * bv.w1};
    for (int k = 0; k < 16; ++k) w[k] = a[k & 3] * b[k >> 2];
}

bool learned_predict(const double w[16], const LearnedSample* const s[16], TableHit& out) {
    double wh = 0, wm = 0, t = 0;
    Vec3 n;
    for (int k = 0; k < 16; ++k) {
        if (w[k] == 0) continue;
        const LearnedSample& c = *s[k];
        if (c.hit) {
            wh += w[k];
            t += w[k] * c.t;
            n += c.n * w[k];
        } else {
            wm += w[k];
        }
    }
    if (!(wh > wm)) return false;
    out.t = std::clamp(t / wh, 0.0, 1.0);
    const double len = length(n);
    out.normal = len > 0 ? n / len : Vec3{0, 0, 1};
    return true;
}

namespace {

std::uint64_t word(const std::uint8_t* p, std::size_t i) {
    std::uint64_t w;
    std::memcpy(&w, p + 8 * i, 8);
    return w;
}

}  // namespace

LearnedTable::LearnedTable(const std::uint8_t* payload, std::size_t size, std::uint64_t entries,
                           const TableContext& ctx)
    : grid_({1, 1, 1}), layout_({1, 1, 1}, 1), entries_(entries), size_(size) {
    using namespace learned;
    if (size < kHeaderWords * 8 || size % 8 != 0) throw std::runtime_error("learned: payload size");
    if (reinterpret_cast<std::uintptr_t>(payload) % 8 != 0)
        throw std::runtime_error("learned: payload not 8-byte aligned");
    if (word(payload, 0) != (kMagic | (std::uint64_t{kVersion} << 32)))
        throw std::runtime_error("learned: wrong magic or version");
    const std::uint64_t w1 = word(payload, 1), w2 = word(payload, 2), w3 = word(payload, 3);
    const std::array<int, 3> cells{static_cast<int>(w1 & 0xFFFFFFFF), static_cast<int>(w1 >> 32),
                                   static_cast<int>(w2 & 0xFFFFFFFF)};
    if (cells != ctx.cells) throw std::runtime_error("learned: payload is for other cells");
    const std::uint64_t step = w2 >> 32;
    widths_ = {static_cast<unsigned>(w3 & 0xFF), static_cast<unsigned>((w3 >> 8) & 0xFF),
               static_cast<unsigned>((w3 >> 16) & 0xFF), static_cast<unsigned>((w3 >> 24) & 0xFF)};
    const LearnedWidths& w = widths_;
    if (step < 1 || step > 256 || w.model_t < 2 || w.model_t > 32 || w.model_n < 2 ||
        w.model_n > 16 || w.ex_t < 1 || w.ex_t > 32 || w.ex_n < 2 || w.ex_n > 16 || (w3 >> 32) != 0)
        throw std::runtime_error("learned: bad step or field widths");
    for (int c : cells)
        if (c < 1) throw std::runtime_error("learned: bad cells");
    grid_ = BoundaryGrid(cells);
    layout_ = LearnedLayout(cells, static_cast<int>(step));
    const std::uint64_t misses = word(payload, 4), hits = word(payload, 5);
    // Counts are bounded before sizes are multiplied, so nothing below can overflow.
    constexpr std::uint64_t kLimit = std::uint64_t{1} << 56;
    if (layout_.samples() >= kLimit || layout_.keys() >= kLimit || misses > layout_.keys() ||
        hits > layout_.keys())
        throw std::runtime_error("learned: bad exception counts");
    const EliasFanoShape ms = EliasFanoShape::for_keys(misses, layout_.keys());
    const EliasFanoShape hs = EliasFanoShape::for_keys(hits, layout_.keys());
    const std::uint64_t model_words = words_for_bits(layout_.samples() * sample_width(w));
    const std::uint64_t ms_words = ms.high_words() + ms.low_words();
    const std::uint64_t hs_words = hs.high_words() + hs.low_words();
    const std::uint64_t value_words = words_for_bits(hits * value_width(w));
    if (kHeaderWords + model_words + ms_words + hs_words + value_words != size / 8)
        throw std::runtime_error("learned: payload size does not match its header");
    const auto* words = reinterpret_cast<const std::uint64_t*>(payload);
    model_ = words + kHeaderWords;
    miss_ex_ = EliasFanoView(model_ + model_words, ms);
    hit_ex_ = EliasFanoView(model_ + model_words + ms_words, hs);
    values_ = model_ + model_words + ms_words + hs_words;
}

std::uint64_t LearnedTable::bytes() const {
    return size_ + miss_ex_.index_bytes() + hit_ex_.index_bytes();
}

bool LearnedTable::lookup(std::uint32_t a, std::uint32_t b, TableHit& hit) const {
    using namespace learned;
    if (a >= grid_.count() || b >= grid_.count() || a == b) return false;
    const GridPoint pa = grid_.point(a), pb = grid_.point(b);
    const std::uint8_t ma = grid_.faces(pa), mb = grid_.faces(pb);
    if (!BoundaryGrid::valid_pair(ma, mb)) return false;
    int fa, fb;
    LearnedLayout::owner(ma, mb, fa, fb);
    const LearnedLayout::Face &A = layout_.face(fa), &B = layout_.face(fb);
    const int au = pa[A.ua], av = pa[A.va], bu = pb[B.ua], bv = pb[B.va];
    const std::uint64_t key = layout_.key_base(fa, fb) +
                              (std::uint64_t(av) * std::uint64_t(A.nu) + std::uint64_t(au)) * B.points() +
                              std::uint64_t(bv) * std::uint64_t(B.nu) + std::uint64_t(bu);
    std::uint64_t rank;
    if (hit_ex_.find(key, rank)) {
        const std::uint64_t code = read_bits(values_, rank * value_width(widths_),
                                             static_cast<unsigned>(value_width(widths_)));
        hit.t = decode_value_t(code, widths_);
        hit.normal = decode_value_n(code, widths_);
        return true;
    }
    if (miss_ex_.find(key, rank)) return false;
    const AxisCell cau = layout_.axis_cell(au, A.nu, A.cu), cav = layout_.axis_cell(av, A.nv, A.cv);
    const AxisCell cbu = layout_.axis_cell(bu, B.nu, B.cu), cbv = layout_.axis_cell(bv, B.nv, B.cv);
    double w[16];
    learned_weights(cau, cav, cbu, cbv, w);
    LearnedSample s[16];
    const LearnedSample* ps[16];
    const std::uint64_t base = layout_.sample_base(fa, fb), width = sample_width(widths_);
    for (int k = 0; k < 16; ++k) {
        ps[k] = &s[k];
        if (w[k] == 0) continue;
        const std::uint64_t ja = std::uint64_t(cav.j0 + ((k >> 1) & 1)) * std::uint64_t(A.cu) +
                                 std::uint64_t(cau.j0 + (k & 1));
        const std::uint64_t jb = std::uint64_t(cbv.j0 + ((k >> 3) & 1)) * std::uint64_t(B.cu) +
                                 std::uint64_t(cbu.j0 + ((k >> 2) & 1));
        const std::uint64_t i = base + ja * B.nodes() + jb;
        s[k] = decode_sample(read_bits(model_, i * width, static_cast<unsigned>(width)), widths_);
    }
    return learned_predict(w, ps, hit);
}

}  // namespace lat
