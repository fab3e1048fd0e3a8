#include "lattice/certify.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>

#include "geometry/shape.h"
#include "lattice/boundary_grid.h"
#include "lattice/rasterizer.h"
#include "util/progress.h"

namespace lat {
namespace {

struct ExactHit {
    std::uint32_t b;
    float t;
    std::uint16_t part, leaf;  // packed as in RawHit
    Crossing crossing() const { return RawHit{0, b, t, 0, 0, part, leaf}.crossing(double(t)); }
};

}  // namespace

CertifyReport certify_table(const LatticeTable& table, const TableContext& ctx, bool progress) {
    const auto start = std::chrono::steady_clock::now();
    const Shape& shape = *ctx.primitive;
    const BoundaryGrid grid(ctx.cells);
    const RasterizeResult exact = rasterize(ctx);
    // The exact hits by entry point, sorted by exit point.
    std::vector<std::vector<ExactHit>> by_entry(grid.count());
    for (const auto& chunk : exact.raw.chunks)
        for (const RawHit& h : chunk) by_entry[h.a].push_back({h.b, h.t, h.part, h.leaf});
    tbb::parallel_for(std::size_t{0}, by_entry.size(), [&](std::size_t a) {
        std::sort(by_entry[a].begin(), by_entry[a].end(),
                  [](const ExactHit& x, const ExactHit& y) { return x.b < y.b; });
    });

    struct Partial {
        std::uint64_t pairs = 0, hits = 0, false_hits = 0, false_misses = 0, both = 0;
        double max_p = 0, sum_p = 0, max_n = 0, sum_n = 0;
    };
    std::mutex mu;
    Partial total;
    std::vector<std::uint8_t> faces(grid.count());
    for (std::uint32_t i = 0; i < grid.count(); ++i) faces[i] = grid.faces(grid.point(i));
    ProgressBar bar("certify", grid.count(), progress);
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, grid.count(), 16), [&](const auto& range) {
        Partial part;
        for (std::uint32_t a = range.begin(); a != range.end(); ++a) {
            const Vec3 pa = to_vec(grid.point(a));
            const auto& hits = by_entry[a];
            std::size_t next = 0;
            for (std::uint32_t b = 0; b < grid.count(); ++b) {
                if (b == a || !BoundaryGrid::valid_pair(faces[a], faces[b])) continue;
                ++part.pairs;
                while (next < hits.size() && hits[next].b < b) ++next;
                const bool exact_hit = next < hits.size() && hits[next].b == b;
                TableHit th;
                const bool table_hit = table.lookup(a, b, th);
                part.hits += exact_hit;
                if (exact_hit != table_hit) {
                    (table_hit ? part.false_hits : part.false_misses) += 1;
                    continue;
                }
                if (!exact_hit) continue;
                const ExactHit& e = hits[next];
                const Vec3 pb = to_vec(grid.point(b));
                const double len = length(pb - pa) * ctx.cell / ctx.sigma;
                const double perr = std::abs(th.t - double(e.t)) * len;
                const Ray seg{pa * ctx.cell, (pb - pa) * ctx.cell};
                const Vec3 n = shape.normal(seg, e.crossing());
                const double c = std::clamp(dot(n, th.normal), -1.0, 1.0);
                const double nerr = std::acos(c) * 180.0 / M_PI;
                ++part.both;
                part.max_p = std::max(part.max_p, perr), part.sum_p += perr;
                part.max_n = std::max(part.max_n, nerr), part.sum_n += nerr;
            }
            bar.add(1);
        }
        const std::lock_guard<std::mutex> lock(mu);
        total.pairs += part.pairs, total.hits += part.hits, total.false_hits += part.false_hits;
        total.false_misses += part.false_misses, total.both += part.both;
        total.max_p = std::max(total.max_p, part.max_p), total.sum_p += part.sum_p;
        total.max_n = std::max(total.max_n, part.max_n), total.sum_n += part.sum_n;
    });
    bar.finish();
    CertifyReport r;
    r.pairs = total.pairs;
    r.exact_hits = total.hits;
    r.false_hits = total.false_hits;
    r.false_misses = total.false_misses;
    r.max_point_error = total.max_p;
    r.mean_point_error = total.both ? total.sum_p / double(total.both) : 0;
    r.max_normal_error_deg = total.max_n;
    r.mean_normal_error_deg = total.both ? total.sum_n / double(total.both) : 0;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
}

}  // namespace lat
