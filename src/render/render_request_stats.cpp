// The figures of a render, as `render --stats` writes them and Python's render() returns them.
#include <nlohmann/json.hpp>

#include "render/render_request.h"
#include "util/memory.h"

namespace lat {

nlohmann::json timeline_json(const dist::Timeline& t) {
    nlohmann::json j = nlohmann::json::object();
    for (int s = 0; s < static_cast<int>(dist::Step::kCount); ++s)
        if (const double ms = t[static_cast<std::size_t>(s)]; ms > 0)
            j[std::string(dist::step_name(static_cast<dist::Step>(s)))] = ms;
    return j;
}

namespace {

// What answered, per primitive: the effective settings, not the requested ones.
nlohmann::json answers_json(const RenderRequest& a, const SceneLattices& lattices) {
    nlohmann::json list = nlohmann::json::array();
    for (const PrimitiveAnswer& p : lattices.answers) {
        nlohmann::json e{{"primitive", p.primitive}, {"where", p.where},
                         {"answered_by", answer_name(p.by)}, {"how", answer_text(p, a.lattice_filter())}};
        if (!p.encoding.empty()) e["encoding"] = p.encoding;
        if (p.by == AnsweredBy::kFilteredTables) e["filter"] = a.filter;
        if (!p.sigma_inv.empty()) e["sigma_inv"] = p.sigma_inv;
        if (p.coverage_rays > 0) e["coverage_rays"] = p.coverage_rays;
        if (p.by == AnsweredBy::kSubRayCrossings) e["sub_rays"] = kSubRays;
        if (!p.why.empty()) e["why"] = p.why;
        list.push_back(std::move(e));
    }
    return list;
}

nlohmann::json rank_json(const RankStats& rs) {
    nlohmann::json j{{"rank", rs.rank},
            {"host", rs.host},
            {"threads", rs.threads},
            {"tiles", rs.tiles},
            {"chunks", rs.chunks},
            {"render_ms", rs.render_ms},
            {"wait_ms", rs.wait_ms},
            {"cpu_ms", rs.cpu_ms},
            {"primary_rays", rs.primary_rays},
            {"shadow_rays", rs.shadow_rays},
            {"peak_memory_bytes", rs.peak_memory_bytes},
            {"timeline_ms", timeline_json(rs.timeline)}};
    for (std::size_t c = 0; c < rs.counted.size(); ++c)
        j[std::string(stats::counter_name(stats::Counter(c)))] = rs.counted[c];
    return j;
}

}  // namespace

nlohmann::json render_stats_json(const RenderRequest& a, const Scene& scene, const ModeResult& r,
                                 const RenderTimings& t) {
    const SceneLattices& lattices = r.lattices;
    const RenderStats& st = r.out.stats;
    nlohmann::json j;
    j["scene"] = a.scene;
    j["output"] = a.output;
    j["mode"] = a.mode;
    if (a.render_mode() == RenderMode::kExact) j["footprint"] = a.footprint;
    j["width"] = scene.camera.width;
    j["height"] = scene.camera.height;
    j["spp"] = std::max(1, a.spp);
    j["sampler"] = r.out.stats.sampler;
    j["threads"] = st.threads;
    j["load_ms"] = t.loaded;
    j["load_cpu_ms"] = t.loaded_cpu;
    j["build_ms"] = r.build_ms;
    j["build_cpu_ms"] = r.build_cpu_ms;
    j["prepare_ms"] = r.prepare_ms;
    j["bytes_added"] = r.bytes_added;
    if (a.answers_instances()) {
        j["primitives"] = answers_json(a, lattices);
        j["lattice_notes"] = lattices.notes;
        j["tables_ms"] = r.prepare_ms;
        j["tables_built"] = lattices.built;
        nlohmann::json builds = nlohmann::json::array();
        for (const SceneLattices::Built& b : lattices.builds) {
            nlohmann::json e{{"primitive", b.primitive}, {"sigma_inv", b.sigma_inv}, {"seconds", b.seconds}};
            if (b.coverage_rays > 0) {
                e["coverage_rays"] = b.coverage_rays;
                e["estimated_cpu_seconds"] = b.estimated_cpu_seconds;
            }
            builds.push_back(std::move(e));
        }
        j["tables_built_list"] = builds;
        j["table_bytes"] = lattices.table_bytes;
        j["table_entries"] = lattices.table_entries;
        j["table_files"] = lattices.paths;
        j["table_visits"] = st.count(stats::Counter::kLatticeVisits);
    }
    if (r.shadow_maps) {
        const ShadowMapReport& m = *r.shadow_maps;
        j["instance_shadows"] = {{"by", "deep-map"},          {"sizes", m.sizes},
                                 {"lights", m.lights},        {"lights_mapped", m.lights_mapped},
                                 {"tiles", m.tiles},          {"tiles_traced", m.tiles_traced},
                                 {"bytes", m.bytes},          {"knots", m.knots}};
    } else if (a.render_mode() == RenderMode::kLattice && scene.shadows) {
        j["instance_shadows"] = {{"by", "rays"}};
    }
    j["option_notes"] = a.notes;
    j["render_ms"] = st.render_ms;
    j["render_cpu_ms"] = st.cpu_ms;
    j["total_ms"] = t.written;
    j["primary_rays"] = st.primary_rays;
    j["shadow_rays"] = st.shadow_rays;
    j["rays_per_second"] = mrays_per_s(st) * 1e6;
    j["peak_memory_bytes"] = peak_rss_bytes();
    if (!st.ranks.empty()) {
        j["mpi_ranks"] = st.ranks.size();
        for (const RankStats& rs : st.ranks) j["ranks"].push_back(rank_json(rs));
    }
    return j;
}

}  // namespace lat
