#include "render/render_request.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <nlohmann/json.hpp>

#include "lattice/encoding.h"
#include "lattice/filtered_shape.h"
#include "lattice/sub_ray_shape.h"
#include "lattice/table.h"
#include "util/memory.h"

namespace lat {
namespace {

template <class Map>
std::vector<std::string> keys(const Map& m) {
    std::vector<std::string> k;
    for (const auto& [name, value] : m) k.emplace_back(name);
    std::sort(k.begin(), k.end());  // as CLI11 lists a std::map's keys
    return k;
}

std::map<std::string, RenderMode> mode_names() {
    std::map<std::string, RenderMode> m;
    for (const ModeDescription& d : render_modes()) m.emplace(std::string(d.name), d.mode);
    return m;
}
const std::map<std::string, RenderMode>& modes_by_name() {
    static const std::map<std::string, RenderMode> m = mode_names();
    return m;
}
const std::map<std::string, SamplerKind>& samplers_by_name() {
    static const std::map<std::string, SamplerKind> m = [] {
        std::map<std::string, SamplerKind> names;
        for (const SamplerDescription& d : samplers()) names.emplace(std::string(d.name), d.kind);
        return names;
    }();
    return m;
}
std::string sampler_help() {
    std::string help = "Where a pixel's samples fall when --spp > 1 (exact, lattice, auto and texture "
                       "modes; particles mode always takes the grid): ";
    for (const SamplerDescription& d : samplers())
        help += std::string(d.name) + (d.kind == kDefaultSampler ? " (the default)" : "") + ": " +
                std::string(d.help) + "; ";
    help.resize(help.size() - 2);
    return help;
}
const std::map<std::string, bool> kOnOff{{"on", true}, {"off", false}};
const std::map<std::string, Instancing> kInstancing{
    {"auto", Instancing::kAuto}, {"always", Instancing::kAlways}, {"never", Instancing::kNever}};
const std::map<std::string, InstanceShadowing> kInstanceShadowing{
    {"rays", InstanceShadowing::kRays}, {"deep-map", InstanceShadowing::kDeepMap}};
LatticeFilter filter_named(const std::string& name) {
    for (const auto& [n, f] : kLatticeFilterNames)
        if (n == name) return f;
    return LatticeFilter::kSmooth;  // unreachable: the choice was checked
}

// Not a range check: its comparisons would let "nan" through.
std::string minutes_check(const std::string& text) {
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    return end != text.c_str() && *end == '\0' && std::isfinite(v) && v >= 0 && v <= 1e7
               ? ""
               : "a number of minutes from 0 to 1e7";
}

std::string mode_help() {
    std::string help;
    for (const ModeDescription& d : render_modes())
        help += (help.empty() ? "" : "; ") + std::string(d.name) + ": " + std::string(d.help);
    return help;
}

std::vector<OptionEntry<TableSpec>> make_table_entries() {
    using E = OptionEntry<TableSpec>;
    std::string names;
    for (const Encoding* e : encodings()) names += (names.empty() ? "" : ", ") + std::string(e->name);
    std::vector<std::string> normals;
    for (const auto& [name, value] : kDenseNormalNames) normals.emplace_back(name);
    std::sort(normals.begin(), normals.end());
    const std::vector<RenderMode> tables{RenderMode::kLattice, RenderMode::kAuto};
    return {
        // Its range is checked where the table is planned (plan_table), the one place for it.
        E{"--sigma-inv",
          "Refine the lattice K times: K x the cells at sigma / K, same box (1 to " +
              std::to_string(kMaxSigmaInv) + ")",
          [](TableSpec& s) { return OptionField{&s.sigma_inv}; }, {}, tables},
        E{"--encoding", "Lattice table encoding: " + names,
          [](TableSpec& s) { return OptionField{&s.encoding}; }, {}, tables},
        E{"--max-point-error", "Quantising encodings: largest point error, in units of sigma",
          [](TableSpec& s) { return OptionField{&s.options.max_point_error}; },
          OptionCheck::positive_number(), tables},
        E{"--max-normal-error", "Quantising encodings: largest normal error, in degrees",
          [](TableSpec& s) { return OptionField{&s.options.max_normal_error_deg}; },
          OptionCheck::positive_number(), tables},
        E{"--dense-normals",
          "dense: normals as octahedral codes (oct), as the part hit, re-evaluated (part), or "
          "whichever is smaller (auto; octahedral where parts are quartics)",
          [](TableSpec& s) {
              return OptionField{ChoiceSetter{[&s](const std::string& name) {
                  for (const auto& [n, v] : kDenseNormalNames)
                      if (n == name) s.options.normals = v;
              }}};
          },
          OptionCheck::one_of(normals), tables},
    };
}

// The table options, writing into the request's TableSpec.
void append_table_entries(std::vector<OptionEntry<RenderRequest>>& out) {
    for (const OptionEntry<TableSpec>& t : table_option_entries()) {
        OptionEntry<RenderRequest> e{t.names, t.help, {}, t.check, t.modes};
        e.field = [f = t.field](RenderRequest& r) { return f(r.spec); };
        out.push_back(std::move(e));
    }
}

std::vector<OptionEntry<RenderRequest>> make_render_entries() {
    using E = OptionEntry<RenderRequest>;
    using M = RenderMode;
    const std::vector<M> tables{M::kLattice, M::kAuto};
    std::vector<E> e;
    e.push_back({"scene", "Scene file (JSON)", [](RenderRequest& r) { return OptionField{&r.scene}; }});
    e.back().required = e.back().command_line_only = true;
    e.push_back({"-o,--output", "Output image: .png, .pfm or .exr",
                 [](RenderRequest& r) { return OptionField{&r.output}; }});
    e.back().required = e.back().command_line_only = true;
    e.push_back({"--threads", "Worker threads (default: all cores)",
                 [](RenderRequest& r) { return OptionField{&r.threads}; }, OptionCheck::in_range(0, 4096)});
    e.push_back({"--spp", "Samples per pixel (1 = the pixel centre; see --sampler)",
                 [](RenderRequest& r) { return OptionField{&r.spp}; }, OptionCheck::in_range(1, 65536)});
    e.push_back({"--sampler", sampler_help(), [](RenderRequest& r) { return OptionField{&r.sampler}; },
                 OptionCheck::one_of(keys(samplers_by_name())),
                 {M::kExact, M::kLattice, M::kAuto, M::kTexture}});
    e.push_back({"--stats", "Write timing and ray counts as JSON",
                 [](RenderRequest& r) { return OptionField{&r.stats}; }});
    e.back().command_line_only = true;
    e.push_back({"--mode", mode_help(), [](RenderRequest& r) { return OptionField{&r.mode}; },
                 OptionCheck::one_of(keys(modes_by_name()))});
    e.push_back({"--texture-size", "texture mode: the baked map's width in texels (height is half)",
                 [](RenderRequest& r) { return OptionField{&r.texture.width}; },
                 OptionCheck::in_range(2, 16384), {M::kTexture}});
    e.push_back({"--texture-subsamples", "texture mode: rays per texel side when baking",
                 [](RenderRequest& r) { return OptionField{&r.texture.subsamples}; },
                 OptionCheck::in_range(1, 16), {M::kTexture}});
    e.push_back({"--shadow-map-size",
                 "particles mode, and lattice mode's --instance-shadows deep-map: texels on a "
                 "side of each light's shadow map (default: 2048 for particles; for deep maps, "
                 "a texel as wide as a camera sample's footprint at the instances)",
                 [](RenderRequest& r) { return OptionField{&r.shadow_map_size}; },
                 OptionCheck::in_range(16, 16384), {M::kParticles, M::kLattice}});
    e.push_back({"--lattice-dir",
                 "Directory of cached lattice tables (default: $LATTICE_CACHE_DIR, "
                 "$XDG_CACHE_HOME/lattice or ~/.cache/lattice)",
                 [](RenderRequest& r) { return OptionField{&r.lattice_dir}; }, {}, tables});
    append_table_entries(e);
    e.push_back({"--filter",
                 "lattice and auto modes: none (point-sampled tables, as rasterized), box (each pair's "
                 "coverage) or smooth (coverage blended over the neighbouring pairs, the "
                 "default unless --encoding names one without coverage); a filter uses the "
                 "coverage encoding",
                 [](RenderRequest& r) { return OptionField{&r.filter}; },
                 OptionCheck::one_of(keys(kLatticeFilterNames)), tables});
    e.push_back({"--lod",
                 "lattice and auto modes with a filter: levels of detail, tables at sigma^-1 = "
                 "K, 2K, 4K as the pixels' footprints need, within --lod-budget (on); or K "
                 "alone (off)",
                 [](RenderRequest& r) { return OptionField{&r.lod}; }, OptionCheck::one_of(keys(kOnOff)), tables});
    e.push_back({"--lod-budget",
                 "lattice and auto modes, --lod on: levels of detail beyond K are built only "
                 "while all the tables the render builds take at most about this many minutes "
                 "of one core together (estimated from the sub-rays each build traces near the "
                 "primitive's parts; 10 minutes are about 5 on 2 cores); past it lattice mode "
                 "reads the finest level within it and auto mode answers the primitive by its "
                 "sub-rays, and the summary says so. A level in the cache is read whatever the "
                 "budget, and costs none of it",
                 [](RenderRequest& r) { return OptionField{&r.lod_budget}; },
                 OptionCheck::by_text(minutes_check), tables});
    e.back().show_default = true;
    e.push_back({"--instance-shadows",
                 "lattice mode with a filter: the shadows instances cast, from shadow rays "
                 "through their tables (rays), or read from a deep shadow map per light traced "
                 "through the same tables as lookups need it (deep-map: --shadow-map-size "
                 "texels a side; shadows of everything else stay rays; a light among the "
                 "instances keeps rays)",
                 [](RenderRequest& r) { return OptionField{&r.instance_shadows}; },
                 OptionCheck::one_of(keys(kInstanceShadowing)), {M::kLattice}});
    e.back().show_default = true;
    e.push_back({"--instancing",
                 "Multi-part objects as Embree instances (always), flattened into one "
                 "hierarchy (never), or flattened unless that would be huge (auto)",
                 [](RenderRequest& r) { return OptionField{&r.instancing}; },
                 OptionCheck::one_of(keys(kInstancing)), {M::kExact, M::kLattice, M::kAuto}});
    e.push_back({"--footprint",
                 "exact mode: each instance answered by its own crossings of " +
                     std::to_string(kExactSubRays) + " x " + std::to_string(kExactSubRays) +
                     " sub-rays across the ray's footprint (a pixel's, split by --spp), their "
                     "partial coverage composited front to back and shadowed per layer: "
                     "antialiased hair at 1 spp (on); or point samples (off)",
                 [](RenderRequest& r) { return OptionField{&r.footprint}; },
                 OptionCheck::one_of(keys(kOnOff)), {M::kExact}});
    e.back().show_default = true;
    e.push_back({"-q,--quiet", "No progress bar or summary line",
                 [](RenderRequest& r) { return OptionField{&r.quiet}; }});
    e.back().flag = e.back().command_line_only = true;
    return e;
}

// The order the notes come in (as the command line has always given them): by the modes an
// option acts in, lattice and auto options first.
int note_rank(const std::vector<RenderMode>& modes) {
    using M = RenderMode;
    if (modes.size() > 2) return 4;
    switch (modes.front()) {
        case M::kLattice: return 0;
        case M::kExact: return 1;
        case M::kTexture: return 2;
        default: return 3;
    }
}

std::vector<std::string> option_notes(const RenderRequest& r,
                                      const std::function<bool(std::string_view)>& given) {
    std::vector<std::pair<int, std::string>> ranked;
    for (const OptionEntry<RenderRequest>& e : render_option_entries()) {
        const std::string name = e.long_name();
        if (e.modes.empty() || !given(name) ||
            std::find(e.modes.begin(), e.modes.end(), r.render_mode()) != e.modes.end())
            continue;
        std::string where;
        for (const RenderMode m : e.modes)
            where += (where.empty() ? "" : ", ") + std::string(mode_description(m).name);
        // --lattice-dir came after the table options before they shared a table.
        const int rank = note_rank(e.modes) * 2 + (name == "--lattice-dir" ? 1 : 0);
        ranked.emplace_back(rank, name + " has no effect in " + r.mode + " mode (it acts in: " + where + ")");
    }
    std::stable_sort(ranked.begin(), ranked.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<std::string> notes;
    for (auto& [rank, text] : ranked) notes.push_back(std::move(text));
    const bool tables = r.render_mode() == RenderMode::kLattice || r.render_mode() == RenderMode::kAuto;
    if (tables && r.lattice_filter() == LatticeFilter::kNone && given("--lod"))
        notes.push_back("--lod has no effect with --filter none (point-sampled tables have one level)");
    const bool deep_maps = r.lattice_filter() != LatticeFilter::kNone &&
                           kInstanceShadowing.at(r.instance_shadows) == InstanceShadowing::kDeepMap;
    if (r.render_mode() == RenderMode::kLattice && r.lattice_filter() == LatticeFilter::kNone &&
        given("--instance-shadows"))
        notes.push_back("--instance-shadows has no effect with --filter none (point-sampled "
                        "tables cast shadows by shadow rays)");
    if (r.render_mode() == RenderMode::kLattice && !deep_maps && given("--shadow-map-size"))
        notes.push_back("--shadow-map-size has no effect in lattice mode without "
                        "--instance-shadows deep-map and a filter");
    if (tables && given("--lod-budget") && (r.lattice_filter() == LatticeFilter::kNone || !kOnOff.at(r.lod)))
        notes.push_back("--lod-budget has no effect without levels of detail (--lod on and a filter)");
    return notes;
}

std::string levels_text(const std::vector<long long>& sigma_inv) {
    std::string text;
    for (const long long k : sigma_inv) text += (text.empty() ? "" : ", ") + std::to_string(k);
    return "sigma^-1 = " + text;
}

}  // namespace

OptionCheck OptionCheck::in_range(int lo, int hi) {
    OptionCheck c;
    c.range = {lo, hi};
    return c;
}
OptionCheck OptionCheck::positive_number() {
    OptionCheck c;
    c.positive = true;
    return c;
}
OptionCheck OptionCheck::one_of(std::vector<std::string> names) {
    OptionCheck c;
    c.choices = std::move(names);
    return c;
}
OptionCheck OptionCheck::by_text(std::string (*check)(const std::string&)) {
    OptionCheck c;
    c.text = check;
    return c;
}

RenderMode RenderRequest::render_mode() const { return modes_by_name().at(mode); }
LatticeFilter RenderRequest::lattice_filter() const { return filter_named(filter); }
bool RenderRequest::footprint_on() const { return kOnOff.at(footprint); }
bool RenderRequest::answers_instances() const {
    return lat::answers_instances(render_mode(), footprint_on());
}

template <class Target>
std::string OptionEntry<Target>::long_name() const {
    const std::size_t comma = names.rfind(',');
    return comma == std::string::npos ? names : names.substr(comma + 1);
}

template <class Target>
std::string OptionEntry<Target>::python_name() const {
    std::string n = long_name();
    n.erase(0, n.find_first_not_of('-'));
    std::replace(n.begin(), n.end(), '-', '_');
    return n;
}

template struct OptionEntry<TableSpec>;
template struct OptionEntry<RenderRequest>;

const std::vector<OptionEntry<TableSpec>>& table_option_entries() {
    static const std::vector<OptionEntry<TableSpec>> entries = make_table_entries();
    return entries;
}

const std::vector<OptionEntry<RenderRequest>>& render_option_entries() {
    static const std::vector<OptionEntry<RenderRequest>> entries = make_render_entries();
    return entries;
}

std::string check_option_value(const std::string& python_name, const OptionCheck& check,
                               const std::variant<long long, double, std::string>& value) {
    const std::string prefix = python_name + ": ";
    if (const auto* text = std::get_if<std::string>(&value)) {
        if (!check.choices.empty() &&
            std::find(check.choices.begin(), check.choices.end(), *text) == check.choices.end()) {
            std::string list;
            for (const std::string& c : check.choices) list += (list.empty() ? "" : ", ") + c;
            return prefix + "'" + *text + "' is not one of " + list;
        }
        return check.text ? (check.text(*text).empty() ? "" : prefix + check.text(*text)) : "";
    }
    const double v = std::holds_alternative<double>(value) ? std::get<double>(value)
                                                            : static_cast<double>(std::get<long long>(value));
    char shown[64];
    std::snprintf(shown, sizeof shown, "%.17g", v);
    if (check.range && !(v >= check.range->first && v <= check.range->second))
        return prefix + shown + " is not in " + std::to_string(check.range->first) + " to " +
               std::to_string(check.range->second);
    if (check.positive && !(v > 0 && std::isfinite(v))) return prefix + shown + " is not a positive number";
    if (check.text && !check.text(shown).empty()) return prefix + shown + ": " + check.text(shown);
    return "";
}

void settle_request(RenderRequest& r, const std::function<bool(std::string_view)>& given) {
    // A filter needs coverage: unless an encoding was asked for, it takes the one with it; an
    // encoding without coverage asked for alone means its point-sampled table.
    const bool encoding_given = given("--encoding");
    if (encoding_given && !given("--filter") && !find_encoding(r.spec.encoding).coverage) r.filter = "none";
    if (r.lattice_filter() != LatticeFilter::kNone && !encoding_given)
        r.spec.encoding = coverage_encoding().name;
    r.notes = option_notes(r, given);
}

ModeSettings mode_settings(const RenderRequest& r) {
    ModeSettings s;
    s.spp = r.spp;
    s.sampler = samplers_by_name().at(r.sampler);
    s.lattice_dir = r.lattice_dir;
    s.spec = r.spec;
    s.filtering.filter = r.lattice_filter();
    s.filtering.lod = kOnOff.at(r.lod);
    s.filtering.max_work = lod_work(r.lod_budget);
    s.footprint = r.footprint_on();
    s.accel.instancing = kInstancing.at(r.instancing);
    s.texture = r.texture;
    s.shadow_map_size = r.shadow_map_size;
    s.instance_shadows = kInstanceShadowing.at(r.instance_shadows);
    return s;
}

std::string answer_text(const PrimitiveAnswer& p, LatticeFilter filter) {
    std::string text;
    switch (p.by) {
        case AnsweredBy::kTable:
            text = "point-sampled " + p.encoding + " table, " + levels_text(p.sigma_inv);
            break;
        case AnsweredBy::kFilteredTables:
            text = std::string(filter == LatticeFilter::kBox ? "box" : "smooth") + "-filtered " +
                   p.encoding + " table" + (p.sigma_inv.size() == 1 ? ", " : "s, ") +
                   levels_text(p.sigma_inv);
            if (p.coverage_rays > 0) text += ", " + std::to_string(p.coverage_rays) + " sub-rays a pair";
            break;
        case AnsweredBy::kSubRayCrossings:
            text = "its own crossings of " + std::to_string(kExactSubRays) + " x " +
                   std::to_string(kExactSubRays) + " sub-rays across each ray's footprint, no table";
            break;
        case AnsweredBy::kExact: text = "exact point samples, no table"; break;
    }
    return text + (p.why.empty() ? "" : " (" + p.why + ")");
}

double mrays_per_s(const RenderStats& st) {
    const std::uint64_t rays = st.primary_rays + st.shadow_rays;
    return st.render_ms > 0 ? static_cast<double>(rays) / (st.render_ms * 1e3) : 0.0;
}

}  // namespace lat
