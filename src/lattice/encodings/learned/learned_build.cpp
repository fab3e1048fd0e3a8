// Building the learned encoding: fit the field to the hits for a few node spacings and widths,
// judge each by the exceptions it needs on a sample of entry points, then predict every pair
// with the best one, exactly as lookups will, and keep the exceptions.
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include "geometry/shape.h"
#include "lattice/boundary_grid.h"
#include "lattice/encoding.h"
#include "lattice/encodings/learned/learned_fit.h"
#include "lattice/encodings/learned/learned_payload.h"
#include "lattice/encodings/learned/learned_table.h"
#include "lattice/octahedral.h"
#include "util/error.h"

namespace lat {
namespace {

using namespace learned;

// The rasterized hits' own normals are 16-bit octahedral codes, within this of the exact ones.
constexpr double kRawNormalMarginDeg = 0.01;
constexpr std::uint32_t kNone = 0xFFFFFFFFu;
constexpr std::size_t kMaxFitPoints = std::size_t{1} << 20;
constexpr std::uint64_t kSamplePairs = 2'000'000;  // pairs each trial is judged on

// What all trials share: the hits by entry point, and the bounds.
struct Fit {
    const TableContext& ctx;
    BoundaryGrid grid;
    std::vector<GridPoint> pts;
    std::vector<std::uint8_t> masks;
    std::vector<const RawHit*> by_a;   // stably sorted by entry point
    std::vector<std::uint64_t> start;  // per entry point, its first hit in by_a
    std::uint64_t valid_pairs = 0;
    double max_point = 0, cos_normal = 1;

    Fit(const RawHits& hits, const TableContext& c, const EncodeOptions& opt);
    // What certify_table compares with.
    Vec3 normal(const RawHit& h) const {
        if (!ctx.primitive) return oct_decode({h.nu, h.nv}, kRawNormalBits);
        const Vec3 pa = to_vec(pts[h.a]), pb = to_vec(pts[h.b]);
        return ctx.primitive->normal({pa * ctx.cell, (pb - pa) * ctx.cell},
                                     h.crossing(double(h.t)));
    }
    // As certify_table measures it.
    double length_sigma(std::uint32_t a, std::uint32_t b) const {
        return length(to_vec(pts[b]) - to_vec(pts[a])) * ctx.cell / ctx.sigma;
    }
    bool point_ok(double t, const RawHit& h) const {
        return std::abs(t - double(h.t)) * length_sigma(h.a, h.b) <= max_point;
    }
};

Fit::Fit(const RawHits& hits, const TableContext& c, const EncodeOptions& opt)
    : ctx(c), grid(c.cells) {
    const std::uint32_t n = grid.count();
    pts.resize(n);
    masks.resize(n);
    std::array<std::uint64_t, 64> per_mask{};
    for (std::uint32_t i = 0; i < n; ++i)
        pts[i] = grid.point(i), masks[i] = grid.faces(pts[i]), ++per_mask[masks[i]];
    for (unsigned x = 1; x < 64; ++x)
        for (unsigned y = 1; y < 64; ++y)
            if (BoundaryGrid::valid_pair(std::uint8_t(x), std::uint8_t(y)))
                valid_pairs += per_mask[x] * per_mask[y] - (x == y ? per_mask[x] : 0);
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
    // Margins keep rounding in certify's arithmetic (acos) from crossing the bounds.
    const double deg = opt.max_normal_error_deg - (ctx.primitive ? 0.0 : kRawNormalMarginDeg);
    if (!(deg > 0) || !(opt.max_point_error > 0))
        throw InputError(
            "learned: the error bounds must be positive (and the normal bound above 0.01 "
            "degrees when the primitive is not at hand)");
    max_point = opt.max_point_error * (1 - 1e-9);
    cos_normal = std::cos(deg * (1 - 1e-6) * M_PI / 180);
}

struct Exception {
    std::uint64_t key;  // a * points + b
    std::uint32_t hit;  // into Fit::by_a, or kNone for "miss"
    int kind;           // ExceptionKind
};

// The exceptions of every stride-th entry point's pairs, in key order; counts the pairs.
std::vector<Exception> find_exceptions(const Fit& fit, const FieldView& field, std::uint32_t stride,
                                       std::uint64_t& pairs) {
    const std::uint32_t n = fit.grid.count();
    const std::uint32_t entries = (n + stride - 1) / stride, per_task = 8;
    const std::uint32_t tasks = (entries + per_task - 1) / per_task;
    std::vector<std::vector<Exception>> found(tasks);
    std::vector<std::uint64_t> counted(tasks, 0);
    tbb::enumerable_thread_specific<std::vector<std::uint32_t>> rows(
        std::vector<std::uint32_t>(n, kNone));
    tbb::parallel_for(std::uint32_t{0}, tasks, [&](std::uint32_t task) {
        std::vector<std::uint32_t>& row = rows.local();
        for (std::uint32_t e = task * per_task; e < std::min(entries, (task + 1) * per_task); ++e) {
            const std::uint32_t a = e * stride;
            for (std::uint64_t i = fit.start[a]; i < fit.start[a + 1]; ++i)
                row[fit.by_a[i]->b] = static_cast<std::uint32_t>(i);
            const Vec3 pa = to_vec(fit.pts[a]);
            for (std::uint32_t b = 0; b < n; ++b) {
                if (b == a || !BoundaryGrid::valid_pair(fit.masks[a], fit.masks[b])) continue;
                ++counted[task];
                TableHit p;
                const bool predicted = field.predict(pa, to_vec(fit.pts[b]), p);
                const std::uint32_t i = row[b];
                if (!predicted && i == kNone) continue;
                int kind = predicted ? kMiss : kHit;
                if (predicted && i != kNone) {
                    const bool t_ok = fit.point_ok(p.t, *fit.by_a[i]);
                    const bool n_ok = dot(fit.normal(*fit.by_a[i]), p.normal) >= fit.cos_normal;
                    if (t_ok && n_ok) continue;
                    kind = t_ok ? kNormal : n_ok ? kT : kHit;
                }
                found[task].push_back({std::uint64_t(a) * n + b, i, kind});
            }
            for (std::uint64_t i = fit.start[a]; i < fit.start[a + 1]; ++i)
                row[fit.by_a[i]->b] = kNone;
        }
    });
    std::vector<Exception> out;
    pairs = 0;
    for (std::uint32_t t = 0; t < tasks; ++t) {
        out.insert(out.end(), found[t].begin(), found[t].end());
        pairs += counted[t];
    }
    return out;
}

// The narrowest widths of the exceptions' t and normals that keep all of them in bounds.
void value_widths(const Fit& fit, const std::vector<Exception>& ex, unsigned& ex_t,
                  unsigned& ex_n) {
    std::vector<std::uint32_t> hits, normals;
    for (const Exception& e : ex) {
        if (e.kind == kHit || e.kind == kT) hits.push_back(e.hit);
        if (e.kind == kHit || e.kind == kNormal) normals.push_back(e.hit);
    }
    ex_t = 1, ex_n = 2;
    const std::uint64_t t_ok = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, hits.size()), ~std::uint64_t{0},
        [&](const auto& r, std::uint64_t m) {
            for (std::size_t k = r.begin(); k != r.end(); ++k) {
                const RawHit& h = *fit.by_a[hits[k]];
                const auto t = static_cast<double>(h.t);
                for (unsigned bits = 1; bits <= 32; ++bits)
                    if (!fit.point_ok(decode_value_t(encode_value_t(t, bits), bits), h))
                        m &= ~(std::uint64_t{1} << bits);
            }
            return m;
        },
        [](std::uint64_t x, std::uint64_t y) { return x & y; });
    ex_t = 0;
    for (unsigned bits = 1; bits <= 32 && !ex_t; ++bits)
        if ((t_ok >> bits) & 1) ex_t = bits;
    if (!ex_t) throw InputError("learned: the point error bound is below what 32-bit t can meet");
    if (normals.empty()) return;
    auto all_pass = [&](unsigned bits) {
        return tbb::parallel_reduce(
            tbb::blocked_range<std::size_t>(0, normals.size()), true,
            [&](const auto& r, bool ok) {
                for (std::size_t k = r.begin(); k != r.end() && ok; ++k) {
                    const Vec3 n = fit.normal(*fit.by_a[normals[k]]);
                    ok = dot(n, oct_decode(oct_encode_precise(n, int(bits)), int(bits))) >=
                         fit.cos_normal;
                }
                return ok;
            },
            [](bool x, bool y) { return x && y; });
    };
    ex_n = 10;
    if (all_pass(ex_n)) {
        while (ex_n > 2 && all_pass(ex_n - 1)) --ex_n;
    } else {
        while (ex_n < 16 && !all_pass(ex_n)) ++ex_n;
        if (!all_pass(ex_n))
            throw InputError(
                "learned: the normal error bound is below what 16-bit normals can meet");
    }
}

// One candidate model, judged on a sample of entry points (or all of them).
struct Trial {
    int m = 0;  // nodes per sigma
    FieldShape shape;
    const FieldFit* fit = nullptr;
    std::vector<std::uint64_t> nodes;
    std::uint64_t model_words = 0, estimate = 0;  // payload bytes, estimated from the sample
    std::vector<Exception> ex;                    // when judged on every entry point
};

ByteBuffer write_payload(const Fit& fit, const Trial& tr, const std::vector<Exception>& ex,
                         LearnedStats* st) {
    Header h;
    h.cells = fit.ctx.cells;
    h.field = tr.shape;
    h.dense = tr.fit->dense;
    value_widths(fit, ex, h.ex_t, h.ex_n);
    std::vector<std::uint64_t> hit_keys, correction_keys;
    for (const Exception& e : ex) (e.kind == kHit ? hit_keys : correction_keys).push_back(e.key);
    h.hits = hit_keys.size(), h.corrections = correction_keys.size();
    const std::uint64_t universe = std::uint64_t(fit.grid.count()) * fit.grid.count();
    const Sections s = sections(h, universe);
    std::vector<std::uint64_t> out;
    out.reserve(s.total());
    const auto head = encode_header(h);
    out.insert(out.end(), head.begin(), head.end());
    for (const auto* part : {&tr.fit->dense_bits, &tr.fit->sign_bits, &tr.nodes})
        out.insert(out.end(), part->begin(), part->end());
    for (const auto& [keys, shape] :
         {std::pair{&hit_keys, s.hits}, std::pair{&correction_keys, s.corrections}}) {
        const auto ef = elias_fano_encode(*keys, shape);
        out.insert(out.end(), ef.begin(), ef.end());
    }
    BitWriter hit_values(h.hits * hit_width(h)), records(h.corrections * record_width(h));
    const unsigned slot = record_width(h) - 2;
    for (const Exception& e : ex) {
        if (e.kind == kMiss) {
            records.put(kMiss, 2 + slot);
            continue;
        }
        const RawHit& r = *fit.by_a[e.hit];
        const std::uint64_t t = encode_value_t(static_cast<double>(r.t), h.ex_t);
        const Oct o = oct_encode_precise(fit.normal(r), static_cast<int>(h.ex_n));
        const std::uint64_t n = o.u | (std::uint64_t{o.v} << h.ex_n);
        if (e.kind == kHit)
            hit_values.put(t | (n << h.ex_t), hit_width(h));
        else
            records.put(std::uint64_t(e.kind) | ((e.kind == kT ? t : n) << 2), 2 + slot);
    }
    for (const auto* w : {&hit_values, &records}) {
        std::vector<std::uint64_t> words = w->words();
        words.resize(w == &hit_values ? s.hit_values : s.records, 0);
        out.insert(out.end(), words.begin(), words.end());
    }
    out.resize(s.total(), 0);
    ByteBuffer payload(out.size() * 8);
    std::memcpy(payload.data(), out.data(), payload.size());
    if (st) {
        st->field = tr.shape;
        st->nodes_per_sigma = tr.m;
        st->dense_bricks = h.dense;
        st->ex_t = h.ex_t, st->ex_n = h.ex_n;
        for (const Exception& e : ex) {
            std::uint64_t* c[] = {&st->miss_exceptions, &st->hit_exceptions, &st->normal_exceptions,
                                  &st->t_exceptions};
            ++*c[e.kind];
        }
        st->model_bytes = 8 * (kHeaderWords + 2 * s.bitmap + s.nodes);
        st->total_bytes = payload.size();
        st->exception_bytes = st->total_bytes - st->model_bytes;
    }
    return payload;
}

}  // namespace

ByteBuffer LearnedTable::build(const RawHits& hits, const TableContext& ctx,
                               const EncodeOptions& opt, LearnedStats* stats) {
    const auto t0 = std::chrono::steady_clock::now();
    const Fit fit(hits, ctx, opt);
    // The surface points the field is fitted to: the hits (a spread subset of a large table).
    const std::size_t every =
        std::max<std::size_t>(1, (fit.by_a.size() + kMaxFitPoints - 1) / kMaxFitPoints);
    std::vector<SurfacePoint> points((fit.by_a.size() + every - 1) / every);
    tbb::parallel_for(std::size_t{0}, points.size(), [&](std::size_t k) {
        const RawHit& h = *fit.by_a[k * every];
        const Vec3 pa = to_vec(fit.pts[h.a]), pb = to_vec(fit.pts[h.b]);
        points[k] = {pa + (pb - pa) * double(h.t), fit.normal(h)};
    });
    const std::uint32_t n = fit.grid.count();
    const auto stride =
        static_cast<std::uint32_t>(std::clamp<std::uint64_t>(fit.valid_pairs / kSamplePairs, 1, n));
    LearnedStats st;
    st.hits = hits.size();
    std::vector<std::unique_ptr<FieldFit>> fits;
    Trial best;
    auto judge = [&](Trial tr) {
        tr.nodes = tr.fit->quantise(tr.shape);
        const FieldView view(tr.shape, tr.fit->dense_bits.data(), tr.fit->sign_bits.data(),
                             tr.nodes.data(), tr.fit->dense);
        std::uint64_t sampled = 0;
        std::vector<Exception> ex = find_exceptions(fit, view, stride, sampled);
        std::array<std::uint64_t, kKinds> count{};
        for (const Exception& e : ex) ++count[std::size_t(e.kind)];
        const double scale = double(fit.valid_pairs) / double(std::max<std::uint64_t>(1, sampled));
        unsigned et, en;
        value_widths(fit, ex, et, en);
        Header h;
        h.field = tr.shape, h.dense = tr.fit->dense, h.ex_t = et, h.ex_n = en;
        h.hits = std::uint64_t(double(count[kHit]) * scale);
        h.corrections = std::uint64_t(double(count[kMiss] + count[kNormal] + count[kT]) * scale);
        tr.estimate = 8 * sections(h, std::uint64_t(n) * n).total();
        char line[256];
        std::snprintf(line, sizeof line,
                      "%2d nodes/sigma, distance %u + normal 2 x %u bits: %llu dense bricks, model "
                      "%llu bytes; on %llu pairs exceptions: %llu miss, %llu hit, %llu normal, "
                      "%llu t; estimate %llu bytes",
                      tr.m, tr.shape.dist_bits, tr.shape.normal_bits,
                      static_cast<unsigned long long>(tr.fit->dense),
                      static_cast<unsigned long long>(8 * tr.nodes.size()),
                      static_cast<unsigned long long>(sampled),
                      static_cast<unsigned long long>(count[kMiss]),
                      static_cast<unsigned long long>(count[kHit]),
                      static_cast<unsigned long long>(count[kNormal]),
                      static_cast<unsigned long long>(count[kT]),
                      static_cast<unsigned long long>(tr.estimate));
        st.trials.push_back(line);
        if (stride == 1) tr.ex = std::move(ex);
        if (!best.fit || tr.estimate < best.estimate) best = std::move(tr);
    };
    // Node spacing first, at middling widths; then the widths at the best spacing.
    for (const int m : {4, 6, 8, 12, 16}) {
        auto ff = std::make_unique<FieldFit>();
        if (!fit_field(points, ctx.cells, ctx.sigma / m / ctx.cell, *ff)) continue;
        Trial tr;
        tr.m = m, tr.fit = ff.get(), tr.shape = ff->shape;
        tr.shape.dist_bits = 8, tr.shape.normal_bits = 9;
        fits.push_back(std::move(ff));
        judge(std::move(tr));
    }
    if (!best.fit) throw InputError("learned: the lattice is too large for the field's grid");
    std::vector<std::pair<unsigned, unsigned>> tried{{8, 9}};
    for (const auto& [dd, dn] : {std::pair{-2, 0}, std::pair{2, 0}, std::pair{0, -1},
                                 std::pair{0, 1}, std::pair{0, -2}, std::pair{0, 2}}) {
        Trial tr;
        tr.m = best.m, tr.fit = best.fit, tr.shape = best.shape;
        tr.shape.dist_bits = static_cast<unsigned>(int(tr.shape.dist_bits) + dd);
        tr.shape.normal_bits = static_cast<unsigned>(int(tr.shape.normal_bits) + dn);
        const std::pair<unsigned, unsigned> w{tr.shape.dist_bits, tr.shape.normal_bits};
        if (std::find(tried.begin(), tried.end(), w) != tried.end()) continue;
        tried.push_back(w);
        judge(std::move(tr));
    }
    std::vector<Exception> ex = std::move(best.ex);
    if (stride != 1) {
        const FieldView view(best.shape, best.fit->dense_bits.data(), best.fit->sign_bits.data(),
                             best.nodes.data(), best.fit->dense);
        std::uint64_t pairs = 0;
        ex = find_exceptions(fit, view, 1, pairs);
    }
    ByteBuffer payload = write_payload(fit, best, ex, &st);
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (stats) *stats = std::move(st);
    return payload;
}

}  // namespace lat
