#include "lattice/cache/table_build.h"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "distributed/job.h"
#include "distributed/timeline.h"
#include "lattice/boundary_grid.h"
#include "util/error.h"
#include "util/memory.h"

namespace lat {
namespace {

std::string lattice_size(const TableHeader& h) {
    return std::to_string(h.cells[0]) + " x " + std::to_string(h.cells[1]) + " x " +
           std::to_string(h.cells[2]) + " cells (sigma^-1 = " + std::to_string(h.sigma_inv) + ")";
}

long double pair_count(const TableHeader& h) {
    return BoundaryGrid::pair_count(h.cells);
}

[[noreturn]] void refuse_memory(const TablePlan& plan, double hit_rate, double bytes,
                                bool lower_bound) {
    const double per_hit = plan.encoding->bytes_per_hit + sizeof(RawHit);
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "the %s table of primitive '%s' at %s would need %s %s (%.3Lg point pairs, "
                  "%s %.0f %% of them %s, at %.1f bytes per hit while building), more than the "
                  "%s of memory available",
                  plan.header.encoding.c_str(), plan.primitive->name.c_str(),
                  lattice_size(plan.header).c_str(), lower_bound ? "at least" : "about",
                  human_bytes(bytes).c_str(), pair_count(plan.header),
                  lower_bound ? "even if only" : "an estimated", hit_rate * 100,
                  lower_bound ? "were hits" : "hits", per_hit,
                  human_bytes(static_cast<double>(available_memory_bytes())).c_str());
    throw InputError(plan.place + buf);
}

void check_points(const TablePlan& plan) {
    const TableHeader& h = plan.header;
    if (!BoundaryGrid::indexable(h.cells))
        throw InputError(plan.place + "a lattice of " + lattice_size(h) +
                         " has too many boundary points to index");
    const std::uint64_t count = BoundaryGrid(h.cells).count();
    if (count > plan.encoding->max_points)
        throw InputError(plan.place + "the " + h.encoding + " encoding keys at most " +
                         std::to_string(plan.encoding->max_points) + " boundary points; a lattice of " +
                         lattice_size(h) + " has " + std::to_string(count));
}

// step(), with a limit it reaches while building (rasterizer.cpp's part numbers, an encoding's
// memory budget) reported as the plan's primitive's.
template <class Step>
auto naming_the_primitive(const TablePlan& plan, Step&& step) {
    try {
        return step();
    } catch (const InputError& e) {
        throw InputError(plan.place + "primitive '" + plan.primitive->name + "': " + e.what());
    }
}

}  // namespace

void check_buildable(const TablePlan& plan) {
    check_inside_box(*plan.primitive, plan.place);
    const double pairs = static_cast<double>(pair_count(plan.header));
    const double per_hit = plan.encoding->bytes_per_hit + sizeof(RawHit);
    const double avail = static_cast<double>(available_memory_bytes());
    // Even a 1 % hit rate is too much: refuse without tracing anything.
    if (avail > 0 && pairs * 0.01 * per_hit > 0.8 * avail)
        refuse_memory(plan, 0.01, pairs * 0.01 * per_hit, true);
    check_points(plan);
    // Even if every pair were a hit, the build would fit: the estimate below could not refuse
    // it, and its tracing (about 512 entry points: a twentieth of the Plate 3 hair at sigma^-1 = 4)
    // would be spent for nothing.
    if (avail <= 0 || pairs * per_hit <= 0.8 * avail) return;
    // Estimate the hit rate by tracing every n-th entry point.
    RasterizeOptions opt;
    opt.keep_hits = false;
    opt.entry_stride = std::max<std::uint32_t>(1, BoundaryGrid(plan.header.cells).count() / 512);
    const RasterizeResult sample = rasterize(plan.context, opt);
    const double rate =
        sample.pairs_traced ? double(sample.hits) / double(sample.pairs_traced) : 0.0;
    const double need = pairs * rate * per_hit;
    if (avail > 0 && need > 0.8 * avail) refuse_memory(plan, rate, need, false);
}

TableBuild build_table_file(const TablePlan& plan, const std::string& path, bool progress,
                            bool across_ranks) {
    // Rank 0 alone checks: it is the one that will hold every hit.
    if (across_ranks) dist::on_root([&] { check_buildable(plan); });
    else check_buildable(plan);
    dist::mark(dist::Step::kChecked);
    TableBuild b;
    b.header = plan.header;
    RasterizeOptions opt;
    opt.progress = progress;
    opt.keep_hits = plan.encoding->needs_hits;
    opt.across_ranks = across_ranks;
    // Hits in the compact form where the encoding takes it (half the memory first touched),
    // unless other ranks send theirs (as raw hits).
    opt.point_hits = opt.keep_hits && plan.encoding->stream_points &&
                     !(across_ranks && dist::distributed());
    b.raster = naming_the_primitive(plan, [&] { return rasterize(plan.context, opt); });
    const auto encode_and_write = [&] {
        const auto t0 = std::chrono::steady_clock::now();
        EncodeOptions options = plan.options;
        options.memory_budget = static_cast<std::size_t>(0.8 * double(available_memory_bytes()));
        options.progress = progress;
        b.header.pairs = b.raster.pairs_eq2;
        b.header.entries = b.raster.hits;
        // The payload goes straight into the file, and the encoding may free the hits as it
        // reads them: the build's peak is then about the hits alone.
        const std::uint64_t payload_bytes =
            write_table_file(path, b.header, [&](PayloadSink& sink) {
                naming_the_primitive(plan, [&] {
                    if (opt.point_hits)
                        plan.encoding->stream_points(std::move(b.raster.points), plan.context,
                                                     options, sink);
                    else
                        encode_payload(*plan.encoding, std::move(b.raster.raw), plan.context,
                                       options, sink);
                });
            });
        b.raster.raw = {};
        b.raster.points = {};
        b.encode_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        b.bytes = payload_bytes + kTableHeaderBytes + b.header.metadata.size();
        dist::mark(dist::Step::kEncoded);
    };
    // Rank 0 encodes every hit while the other ranks wait: with their cores too, on its node.
    if (across_ranks) dist::on_root_with_node_threads(encode_and_write);
    else encode_and_write();
    return b;
}

}  // namespace lat
