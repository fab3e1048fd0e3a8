// lattice_visits SCENE.json --lattice-dir DIR [--encoding E] [--sigma-inv K] [--threads N] [-o
// OUT.png]
//
// Counts lattice visits: how often the renderer asks a lattice instance about a ray, which
// `lattice render --stats` does not report. Renders the scene in lattice mode with every
// primitive's lattice shape wrapped in a shape that counts the calls and forwards them
// unchanged, and prints JSON: rays, visits by kind, and the (slower, counted) render time.
// The table must already be in the cache (bench/complexity.py rasterizes it first). Timings
// for the benchmark come from `lattice render` itself, never from this wrapped render. With
// -o it writes the image, which must equal `lattice render`'s (the wrapper changes nothing).
#include <tbb/global_control.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "coverage/sheets.h"
#include "geometry/lattice_source.h"
#include "geometry/parts.h"
#include "io/image.h"
#include "render/modes/integrators.h"
#include "render/modes/scene_lattices.h"
#include "scene/scene_loader.h"

namespace {

// Relaxed atomics: the counts are exact; the contention only slows this counting render.
struct Counts {
    std::atomic<std::uint64_t> intersect{0}, occluded{0}, spans{0}, shading{0};
};

class CountingShape final : public lat::Shape,
                            public lat::SheetSource,
                            public lat::Parts,
                            public lat::CullParts,
                            public lat::LatticeSource {
public:
    CountingShape(std::shared_ptr<const lat::Shape> s, Counts& c)
        : s_(std::move(s)), sheets_(lat::sheet_source(*s_)), parts_(*s_), cull_(*s_), source_(*s_),
          c_(c) {}

    lat::Bounds3 bounds() const override { return s_->bounds(); }
    bool intersect(const lat::Ray& r, double tmin, double tmax, lat::Crossing& hit) const override {
        c_.intersect.fetch_add(1, std::memory_order_relaxed);
        return s_->intersect(r, tmin, tmax, hit);
    }
    int sheets(const lat::Ray& r, double tmin, double tmax,
               std::span<lat::SheetCrossing, lat::kMaxSheets> out) const override {
        c_.intersect.fetch_add(1, std::memory_order_relaxed);
        return lat::sheets_of(*s_, sheets_, r, tmin, tmax, out);
    }
    bool occluded(const lat::Ray& r, double tmin, double tmax) const override {
        c_.occluded.fetch_add(1, std::memory_order_relaxed);
        return s_->occluded(r, tmin, tmax);
    }
    void spans(const lat::Ray& r, lat::SpanList& out) const override {
        c_.spans.fetch_add(1, std::memory_order_relaxed);
        s_->spans(r, out);
    }
    // The shaded hit's surface: not a visit (a hit table's crossing already carries it).
    lat::Vec3 normal(const lat::Ray& r, const lat::Crossing& c) const override {
        return s_->normal(r, c);
    }
    lat::SurfacePoint surface(const lat::Ray& r, const lat::Crossing& c) const override {
        c_.shading.fetch_add(1, std::memory_order_relaxed);
        return s_->surface(r, c);
    }
    double surface_tolerance() const override { return s_->surface_tolerance(); }
    bool inside(lat::Vec3 p) const override { return s_->inside(p); }
    std::size_t part_count() const override { return parts_.part_count(); }
    // What the accelerator weighs (shadow rays' kept blockers) as the shape's own.
    double intersect_cost() const override { return source_.intersect_cost(); }
    bool names_surface(const lat::Crossing& c) const override { return source_.names_surface(c); }
    std::uint32_t surface_count() const override { return source_.surface_count(); }
    lat::Bounds3 part_bounds(std::size_t i) const override { return parts_.part_bounds(i); }
    lat::Bounds3 part_bounds(std::size_t i, const lat::Transform& xf) const override {
        return parts_.part_bounds(i, xf);
    }
    lat::Bounds3 placed_bounds(const lat::Transform& xf) const override {
        return s_->placed_bounds(xf);
    }
    bool intersect_part(std::size_t i, const lat::Ray& r, double tmin, double tmax,
                        lat::Crossing& hit) const override {
        c_.intersect.fetch_add(1, std::memory_order_relaxed);
        return parts_.intersect_part(i, r, tmin, tmax, hit);
    }
    bool occluded_part(std::size_t i, const lat::Ray& r, double tmin, double tmax) const override {
        c_.occluded.fetch_add(1, std::memory_order_relaxed);
        return parts_.occluded_part(i, r, tmin, tmax);
    }
    void part_spans(std::size_t i, const lat::Ray& r, lat::SpanList& out) const override {
        c_.spans.fetch_add(1, std::memory_order_relaxed);
        parts_.part_spans(i, r, out);
    }
    void part_spheres(std::size_t i, std::vector<lat::BoundingSphere>& out) const override {
        parts_.part_spheres(i, out);
    }
    std::size_t cull_count() const override { return cull_.cull_count(); }
    lat::Bounds3 cull_bounds(std::size_t i, const lat::Transform& xf, double widest) const override {
        return cull_.cull_bounds(i, xf, widest);
    }
    bool cull_meets(std::size_t i, const lat::Ray& r) const override {
        return cull_.cull_meets(i, r);
    }
    bool cull_capsule(std::size_t i, const lat::Transform& xf, double widest,
                      lat::Capsule& out) const override {
        return cull_.cull_capsule(i, xf, widest, out);
    }

private:
    std::shared_ptr<const lat::Shape> s_;
    const lat::SheetSource* sheets_;  // s_'s, if it has one: forwarded unchanged
    lat::ShapeParts parts_;           // s_'s parts, cull parts and lattice answers, forwarded
    lat::ShapeCull cull_;
    lat::ShapeSource source_;
    Counts& c_;
};

int usage() {
    std::fprintf(
        stderr,
        "usage: lattice_visits SCENE.json --lattice-dir DIR [--encoding E] [--sigma-inv K] "
        "[--threads N] [-o OUT.png]\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    std::string scene_file, dir, output;
    lat::TableSpec spec;
    int threads = 0;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const bool has_value = i + 1 < argc;
        if (a == "--lattice-dir" && has_value)
            dir = argv[++i];
        else if (a == "--encoding" && has_value)
            spec.encoding = argv[++i];
        else if (a == "--sigma-inv" && has_value)
            spec.sigma_inv = std::atoi(argv[++i]);
        else if (a == "--threads" && has_value)
            threads = std::atoi(argv[++i]);
        else if (a == "-o" && has_value)
            output = argv[++i];
        else if (scene_file.empty() && a[0] != '-')
            scene_file = a;
        else
            return usage();
    }
    if (scene_file.empty() || dir.empty()) return usage();
    try {
        std::unique_ptr<tbb::global_control> limit;
        if (threads > 0)
            limit = std::make_unique<tbb::global_control>(
                tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        const lat::Scene scene = lat::load_scene(scene_file);
        const lat::TableCache cache(dir);
        const lat::SceneLattices lattices = lat::scene_lattices(scene, cache, spec, false);
        Counts counts;
        std::vector<std::shared_ptr<const lat::Shape>> wrapped;
        for (const auto& s : lattices.shapes)
            wrapped.push_back(s ? std::make_shared<CountingShape>(s, counts) : nullptr);
        const lat::TracedScene rs(
            scene, [&wrapped](int p) { return wrapped[static_cast<std::size_t>(p)]; });
        const lat::RenderOutput out = lat::render_exact(rs, {});
        if (!output.empty()) lat::write_png(output, out.display);
        std::printf(
            "{\"encoding\": \"%s\", \"tables_built\": %d, \"primary_rays\": %llu, "
            "\"shadow_rays\": %llu, \"intersect\": %llu, \"occluded\": %llu, \"spans\": %llu, "
            "\"shading_calls\": %llu, \"counted_render_ms\": %.3f}\n",
            spec.encoding.c_str(), lattices.built,
            static_cast<unsigned long long>(out.stats.primary_rays),
            static_cast<unsigned long long>(out.stats.shadow_rays),
            static_cast<unsigned long long>(counts.intersect.load()),
            static_cast<unsigned long long>(counts.occluded.load()),
            static_cast<unsigned long long>(counts.spans.load()),
            static_cast<unsigned long long>(counts.shading.load()), out.stats.render_ms);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "lattice_visits: error: %s\n", e.what());
        return 2;
    }
    return 0;
}
