// Building the learned encoding: the model's samples are the hits at the coarse pairs; every
// owned fine pair is then predicted exactly as lookups will, and compared with its hit.
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <chrono>
#include <cmath>
#include <cstring>

#include "geometry/shape.h"
#include "lattice/encodings.h"
#include "lattice/learned_payload.h"
#include "util/error.h"

namespace lat {
namespace {

using namespace learned;

// The rasterized hits' own normals are 16-bit octahedral codes, within this of the exact ones.
constexpr double kRawNormalMarginDeg = 0.01;
constexpr std::uint32_t kNone = 0xFFFFFFFFu;

Vec3 vec_of(const GridPoint& g) { return {double(g.x), double(g.y), double(g.z)}; }

// What all trials share: the hits by entry point, their reference normals, and the bounds.
struct Fit {
    const TableContext& ctx;
    BoundaryGrid grid;
    std::vector<GridPoint> pts;
    std::vector<std::uint8_t> masks;
    std::vector<const RawHit*> by_a;   // stably sorted by entry point
    std::vector<std::uint64_t> start;  // per entry point, its first hit in by_a
    std::vector<Vec3> normal;          // per by_a entry: what certify_table compares with
    double max_point = 0, cos_normal = 1;

    Fit(const RawHits& hits, const TableContext& c, const EncodeOptions& opt);
    // As certify_table measures it.
    double length_sigma(std::uint32_t a, std::uint32_t b) const {
        return length(vec_of(pts[b]) - vec_of(pts[a])) * ctx.cell / ctx.sigma;
    }
    bool within(const TableHit& p, std::uint64_t i, double len) const {
        return std::abs(p.t - double(by_a[i]->t)) * len <= max_point &&
               dot(normal[i], p.normal) >= cos_normal;
    }
};

Fit::Fit(const RawHits& hits, const TableContext& c, const EncodeOptions& opt)
    : ctx(c), grid(c.cells) {
    const std::uint32_t n = grid.count();
    pts.resize(n);
    masks.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) pts[i] = grid.point(i), masks[i] = grid.faces(pts[i]);
    if (hits.size() >= kNone) throw std::length_error("learned: too many hits");
    start.assign(n + 1, 0);
    for (const auto& ch : hits.chunks)
        for (const RawHit& h : ch) {
            if (h.a >= n || h.b >= n || h.a == h.b)
                throw std::invalid_argument("learned: hit with a bad point id");
            ++start[h.a + 1];
        }
    for (std::uint32_t i = 0; i < n; ++i) start[i + 1] += start[i];
    by_a.resize(hits.size());
    std::vector<std::uint64_t> next(start.begin(), start.end() - 1);
    for (const auto& ch : hits.chunks)
        for (const RawHit& h : ch) by_a[next[h.a]++] = &h;
    normal.resize(by_a.size());
    tbb::parallel_for(std::size_t{0}, by_a.size(), [&](std::size_t i) {
        const RawHit& h = *by_a[i];
        if (!ctx.primitive) {
            normal[i] = oct_decode({h.nu, h.nv}, kRawNormalBits);
            return;
        }
        const Vec3 pa = vec_of(pts[h.a]), pb = vec_of(pts[h.b]);
        const Ray seg{pa * ctx.cell, (pb - pa) * ctx.cell};
        normal[i] = ctx.primitive->normal(seg, {double(h.t), h.part, h.leaf});
    });
    // Margins keep rounding in certify's arithmetic (acos) from crossing the bounds.
    max_point = opt.max_point_error * (1 - 1e-9);
    const double deg = opt.max_normal_error_deg - (ctx.primitive ? 0.0 : kRawNormalMarginDeg);
    if (!(deg > 0) || !(opt.max_point_error > 0))
        throw InputError("learned: the error bounds must be positive (and the normal bound above " +
                         std::to_string(kRawNormalMarginDeg) + " degrees without the primitive)");
    cos_normal = std::cos(deg * (1 - 1e-6) * M_PI / 180);
}

struct Exception {
    std::uint64_t key;
    std::uint32_t hit;  // into Fit::by_a, or kNone for "miss"
};

struct Trial {
    int step = 0;
    LearnedWidths widths;
    std::vector<std::uint64_t> codes;  // per sample
    std::vector<Exception> ex;         // sorted by key
    std::uint64_t misses = 0, hits = 0;
    std::uint64_t model_words = 0, exception_words = 0;
    std::uint64_t bytes() const { return 8 * (kHeaderWords + model_words + exception_words); }
};

// The ids of a face's points (fine: every point; coarse: the nodes), in face-local order.
std::vector<std::uint32_t> face_ids(const Fit& fit, const LearnedLayout& L, int f, bool coarse) {
    const LearnedLayout::Face& F = L.face(f);
    const int nu = coarse ? F.cu : F.nu, nv = coarse ? F.cv : F.nv, s = coarse ? L.step() : 1;
    std::vector<std::uint32_t> ids;
    ids.reserve(static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv));
    for (int v = 0; v < nv; ++v)
        for (int u = 0; u < nu; ++u) {
            GridPoint p;
            p[BoundaryGrid::face_axis(f)] = fit.grid.face_level(f);
            p[F.ua] = std::min(u * s, F.nu - 1);
            p[F.va] = std::min(v * s, F.nv - 1);
            ids.push_back(fit.grid.id(p));
        }
    return ids;
}

struct Faces {
    std::array<std::vector<std::uint32_t>, 6> fine, nodes;
};

// The samples: each coarse pair's hit, quantised. Parallel over (face, node).
void fill_samples(const Fit& fit, const LearnedLayout& L, const Faces& ids, Trial& tr) {
    tr.codes.assign(L.samples(), 0);
    std::vector<std::pair<int, std::uint32_t>> tasks;
    for (int f = 0; f < 6; ++f)
        for (std::uint32_t j = 0; j < ids.nodes[f].size(); ++j) tasks.push_back({f, j});
    tbb::enumerable_thread_specific<std::vector<std::uint32_t>> rows(
        std::vector<std::uint32_t>(fit.grid.count(), kNone));
    tbb::parallel_for(std::size_t{0}, tasks.size(), [&](std::size_t k) {
        const auto [fa, ja] = tasks[k];
        std::vector<std::uint32_t>& row = rows.local();
        const std::uint32_t a = ids.nodes[fa][ja];
        for (std::uint64_t i = fit.start[a]; i < fit.start[a + 1]; ++i)
            row[fit.by_a[i]->b] = static_cast<std::uint32_t>(i);
        for (int fb = 0; fb < 6; ++fb) {
            if (fb == fa) continue;
            std::uint64_t out = L.sample_base(fa, fb) + ja * L.face(fb).nodes();
            for (const std::uint32_t b : ids.nodes[fb]) {
                const std::uint32_t i = row[b];
                tr.codes[out++] = i == kNone ? encode_sample(false, 0, {}, tr.widths)
                                             : encode_sample(true, fit.by_a[i]->t, fit.normal[i], tr.widths);
            }
        }
        for (std::uint64_t i = fit.start[a]; i < fit.start[a + 1]; ++i) row[fit.by_a[i]->b] = kNone;
    });
}

struct Scratch {
    std::vector<std::uint32_t> rows;  // per owned entry point: hit index by exit point id
    std::array<std::vector<LearnedSample>, 4> dec;
    std::vector<std::uint8_t> live;  // per exit cell: some corner sample hits
};

// Every owned pair whose entry point lies in coarse cell (ju, jv) of face fa.
void check_cell(const Fit& fit, const LearnedLayout& L, const Faces& ids, const Trial& tr, int fa,
                int ju, int jv, Scratch& s, std::vector<Exception>& out) {
    const LearnedLayout::Face& A = L.face(fa);
    const int st = L.step();
    const int u0 = ju * st, u1 = ju == A.cu - 2 ? A.nu - 1 : u0 + st - 1;
    const int v0 = jv * st, v1 = jv == A.cv - 2 ? A.nv - 1 : v0 + st - 1;
    const std::uint32_t count = fit.grid.count();
    const auto nrows = static_cast<std::size_t>((u1 - u0 + 1) * (v1 - v0 + 1));
    if (s.rows.size() < nrows * count) s.rows.assign(nrows * count, kNone);
    auto a_of = [&](int r) { return ids.fine[fa][static_cast<std::size_t>((v0 + r / (u1 - u0 + 1)) * A.nu + u0 + r % (u1 - u0 + 1))]; };
    for (std::size_t r = 0; r < nrows; ++r) {
        const std::uint32_t a = a_of(static_cast<int>(r));
        for (std::uint64_t i = fit.start[a]; i < fit.start[a + 1]; ++i)
            s.rows[r * count + fit.by_a[i]->b] = static_cast<std::uint32_t>(i);
    }
    for (int fb = 0; fb < 6; ++fb) {
        if (fb == fa) continue;
        const LearnedLayout::Face& B = L.face(fb);
        const std::uint64_t nb = B.nodes(), base = L.sample_base(fa, fb);
        for (int k = 0; k < 4; ++k) {
            const std::uint64_t ja = std::uint64_t(jv + (k >> 1)) * std::uint64_t(A.cu) + std::uint64_t(ju + (k & 1));
            s.dec[k].resize(nb);
            for (std::uint64_t jb = 0; jb < nb; ++jb)
                s.dec[k][jb] = decode_sample(tr.codes[base + ja * nb + jb], tr.widths);
        }
        const int cells_u = B.cu - 1, cells_v = B.cv - 1;
        s.live.assign(static_cast<std::size_t>(cells_u * cells_v), 0);
        for (int cv = 0; cv < cells_v; ++cv)
            for (int cu = 0; cu < cells_u; ++cu)
                for (int k = 0; k < 16; ++k)
                    s.live[std::size_t(cv * cells_u + cu)] |=
                        s.dec[k & 3][std::size_t((cv + (k >> 3)) * B.cu + cu + ((k >> 2) & 1))].hit;
        for (std::size_t r = 0; r < nrows; ++r) {
            const std::uint32_t a = a_of(static_cast<int>(r));
            const std::uint8_t ma = fit.masks[a];
            const int au = fit.pts[a][A.ua], av = fit.pts[a][A.va];
            const AxisCell cau = L.axis_cell(au, A.nu, A.cu), cav = L.axis_cell(av, A.nv, A.cv);
            const std::uint64_t key_a = L.key_base(fa, fb) +
                                        (std::uint64_t(av) * std::uint64_t(A.nu) + std::uint64_t(au)) * B.points();
            const std::uint32_t* row = &s.rows[r * count];
            auto owned = [&](std::uint32_t b) {
                if (b == a || !BoundaryGrid::valid_pair(ma, fit.masks[b])) return false;
                int ga, gb;
                LearnedLayout::owner(ma, fit.masks[b], ga, gb);
                return ga == fa && gb == fb;
            };
            // Pairs in live exit cells: predicted and compared.
            for (int bv = 0; bv < B.nv; ++bv) {
                const AxisCell cbv = L.axis_cell(bv, B.nv, B.cv);
                for (int bu = 0; bu < B.nu; ++bu) {
                    const AxisCell cbu = L.axis_cell(bu, B.nu, B.cu);
                    if (!s.live[std::size_t(cbv.j0 * cells_u + cbu.j0)]) continue;
                    const std::uint32_t b = ids.fine[fb][std::size_t(bv * B.nu + bu)];
                    if (!owned(b)) continue;
                    double w[16];
                    learned_weights(cau, cav, cbu, cbv, w);
                    const LearnedSample* ps[16];
                    for (int k = 0; k < 16; ++k)
                        ps[k] = &s.dec[k & 3][std::size_t((cbv.j0 + (k >> 3)) * B.cu + cbu.j0 + ((k >> 2) & 1))];
                    TableHit p;
                    const bool predicted = learned_predict(w, ps, p);
                    const std::uint32_t i = row[b];
                    if (!predicted && i == kNone) continue;
                    if (predicted && i != kNone && fit.within(p, i, fit.length_sigma(a, b))) continue;
                    out.push_back({key_a + std::uint64_t(bv) * std::uint64_t(B.nu) + std::uint64_t(bu), i});
                }
            }
            // Hits in dead exit cells: the model misses them all.
            for (std::uint64_t i = fit.start[a]; i < fit.start[a + 1]; ++i) {
                const std::uint32_t b = fit.by_a[i]->b;
                if (!(fit.masks[b] >> fb & 1) || !owned(b)) continue;
                const int bu = fit.pts[b][B.ua], bv = fit.pts[b][B.va];
                const int cu = L.axis_cell(bu, B.nu, B.cu).j0, cv = L.axis_cell(bv, B.nv, B.cv).j0;
                if (s.live[std::size_t(cv * cells_u + cu)]) continue;
                out.push_back({key_a + std::uint64_t(bv) * std::uint64_t(B.nu) + std::uint64_t(bu),
                               static_cast<std::uint32_t>(i)});
            }
        }
    }
    for (std::size_t r = 0; r < nrows; ++r) {
        const std::uint32_t a = a_of(static_cast<int>(r));
        for (std::uint64_t i = fit.start[a]; i < fit.start[a + 1]; ++i) s.rows[r * count + fit.by_a[i]->b] = kNone;
    }
}

// The narrowest exception field widths that keep every hit exception within the bounds.
void choose_value_widths(const Fit& fit, Trial& tr) {
    std::vector<std::uint32_t> hit_ex;
    for (const Exception& e : tr.ex)
        if (e.hit != kNone) hit_ex.push_back(e.hit);
    tr.widths.ex_t = 1, tr.widths.ex_n = 2;
    if (hit_ex.empty()) return;
    // t: a mask of the widths 1..32 that suffice, over all exceptions.
    const std::uint64_t t_ok = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, hit_ex.size()), ~std::uint64_t{0},
        [&](const auto& r, std::uint64_t m) {
            for (std::size_t k = r.begin(); k != r.end(); ++k) {
                const RawHit& h = *fit.by_a[hit_ex[k]];
                const double len = fit.length_sigma(h.a, h.b);
                for (unsigned bits = 1; bits <= 32; ++bits) {
                    const double t = double(encode_value_t(h.t, bits)) / double((std::uint64_t{1} << bits) - 1);
                    if (!(std::abs(t - double(h.t)) * len <= fit.max_point)) m &= ~(std::uint64_t{1} << bits);
                }
            }
            return m;
        },
        [](std::uint64_t x, std::uint64_t y) { return x & y; });
    tr.widths.ex_t = 0;
    for (unsigned bits = 1; bits <= 32 && !tr.widths.ex_t; ++bits)
        if (t_ok >> bits & 1) tr.widths.ex_t = bits;
    if (!tr.widths.ex_t) throw InputError("learned: the point error bound is below what 32-bit t can meet");
    auto all_pass = [&](unsigned bits) {
        return tbb::parallel_reduce(
            tbb::blocked_range<std::size_t>(0, hit_ex.size()), true,
            [&](const auto& r, bool ok) {
                for (std::size_t k = r.begin(); k != r.end() && ok; ++k) {
                    const Vec3 n = fit.normal[hit_ex[k]];
                    ok = dot(n, oct_decode(oct_encode_precise(n, int(bits)), int(bits))) >= fit.cos_normal;
                }
                return ok;
            },
            [](bool x, bool y) { return x && y; });
    };
    unsigned bits = 10;
    if (all_pass(bits)) {
        while (bits > 2 && all_pass(bits - 1)) --bits;
    } else {
        while (bits < 16 && !all_pass(++bits)) {}
        if (!all_pass(bits)) throw InputError("learned: the normal error bound is below what 16-bit normals can meet");
    }
    tr.widths.ex_n = bits;
}

Trial run_trial(const Fit& fit, int step, unsigned mt, unsigned mn) {
    Trial tr;
    tr.step = step;
    tr.widths.model_t = mt, tr.widths.model_n = mn;
    const LearnedLayout L(fit.ctx.cells, step);
    Faces ids;
    for (int f = 0; f < 6; ++f) ids.fine[f] = face_ids(fit, L, f, false), ids.nodes[f] = face_ids(fit, L, f, true);
    fill_samples(fit, L, ids, tr);
    std::vector<std::array<int, 3>> tasks;  // (face, cell u, cell v)
    for (int f = 0; f < 6; ++f)
        for (int jv = 0; jv + 1 < L.face(f).cv; ++jv)
            for (int ju = 0; ju + 1 < L.face(f).cu; ++ju) tasks.push_back({f, ju, jv});
    std::vector<std::vector<Exception>> found(tasks.size());
    tbb::enumerable_thread_specific<Scratch> scratch;
    tbb::parallel_for(std::size_t{0}, tasks.size(), [&](std::size_t k) {
        check_cell(fit, L, ids, tr, tasks[k][0], tasks[k][1], tasks[k][2], scratch.local(), found[k]);
    });
    for (auto& f : found) tr.ex.insert(tr.ex.end(), f.begin(), f.end());
    tbb::parallel_sort(tr.ex.begin(), tr.ex.end(), [](const Exception& x, const Exception& y) { return x.key < y.key; });
    for (const Exception& e : tr.ex) (e.hit == kNone ? tr.misses : tr.hits) += 1;
    choose_value_widths(fit, tr);
    const EliasFanoShape ms = EliasFanoShape::for_keys(tr.misses, L.keys());
    const EliasFanoShape hs = EliasFanoShape::for_keys(tr.hits, L.keys());
    tr.model_words = words_for_bits(L.samples() * sample_width(tr.widths));
    tr.exception_words = ms.high_words() + ms.low_words() + hs.high_words() + hs.low_words() +
                         words_for_bits(tr.hits * value_width(tr.widths));
    return tr;
}

ByteBuffer write_payload(const Fit& fit, const Trial& tr) {
    const LearnedLayout L(fit.ctx.cells, tr.step);
    std::vector<std::uint64_t> out(kHeaderWords);
    const auto& c = fit.ctx.cells;
    out[0] = kMagic | (std::uint64_t{kVersion} << 32);
    out[1] = std::uint64_t(std::uint32_t(c[0])) | (std::uint64_t(std::uint32_t(c[1])) << 32);
    out[2] = std::uint64_t(std::uint32_t(c[2])) | (std::uint64_t(tr.step) << 32);
    const LearnedWidths& w = tr.widths;
    out[3] = w.model_t | (w.model_n << 8) | (w.ex_t << 16) | (std::uint64_t{w.ex_n} << 24);
    out[4] = tr.misses, out[5] = tr.hits;
    BitWriter model(L.samples() * sample_width(w));
    for (const std::uint64_t code : tr.codes) model.put(code, static_cast<unsigned>(sample_width(w)));
    out.insert(out.end(), model.words().begin(), model.words().end());
    out.resize(kHeaderWords + tr.model_words, 0);
    std::vector<std::uint64_t> miss_keys, hit_keys;
    BitWriter values(tr.hits * value_width(w));
    for (const Exception& e : tr.ex) {
        if (e.hit == kNone) {
            miss_keys.push_back(e.key);
            continue;
        }
        hit_keys.push_back(e.key);
        const RawHit& h = *fit.by_a[e.hit];
        const Oct o = oct_encode_precise(fit.normal[e.hit], static_cast<int>(w.ex_n));
        values.put(encode_value_t(h.t, w.ex_t), w.ex_t);
        values.put(o.u, w.ex_n);
        values.put(o.v, w.ex_n);
    }
    for (const auto& [keys, n] : {std::pair{&miss_keys, tr.misses}, std::pair{&hit_keys, tr.hits}}) {
        const auto ef = elias_fano_encode(*keys, EliasFanoShape::for_keys(n, L.keys()));
        out.insert(out.end(), ef.begin(), ef.end());
    }
    out.insert(out.end(), values.words().begin(), values.words().end());
    out.resize(kHeaderWords + tr.model_words + tr.exception_words, 0);
    ByteBuffer payload(out.size() * 8);
    std::memcpy(payload.data(), out.data(), payload.size());
    return payload;
}

}  // namespace

ByteBuffer LearnedTable::build(const RawHits& hits, const TableContext& ctx, const EncodeOptions& opt,
                               LearnedStats* stats) {
    const auto t0 = std::chrono::steady_clock::now();
    const Fit fit(hits, ctx, opt);
    Trial best;
    LearnedStats st;
    for (int step : {2, 3, 4})
        for (unsigned mt : {10u, 12u})
            for (unsigned mn : {8u, 10u}) {
                Trial tr = run_trial(fit, step, mt, mn);
                char line[200];
                std::snprintf(line, sizeof line,
                              "step %d model t %u n %u: %llu hit + %llu miss exceptions, t %u n %u bits, "
                              "model %llu + exceptions %llu bytes",
                              step, mt, mn, static_cast<unsigned long long>(tr.hits),
                              static_cast<unsigned long long>(tr.misses), tr.widths.ex_t, tr.widths.ex_n,
                              static_cast<unsigned long long>(8 * tr.model_words),
                              static_cast<unsigned long long>(8 * tr.exception_words));
                st.trials.push_back(line);
                if (best.step == 0 || tr.bytes() < best.bytes()) best = std::move(tr);
            }
    ByteBuffer payload = write_payload(fit, best);
    if (stats) {
        st.step = best.step;
        st.widths = best.widths;
        st.hits = hits.size();
        st.hit_exceptions = best.hits;
        st.miss_exceptions = best.misses;
        st.model_bytes = 8 * best.model_words;
        st.exception_bytes = 8 * best.exception_words;
        st.total_bytes = payload.size();
        st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        *stats = std::move(st);
    }
    return payload;
}

}  // namespace lat
