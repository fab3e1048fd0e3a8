#pragma once
// What a user asks of a render, and the one table of its options: the command line (`lattice
// render`, apps/lattice) and the Python module (python/) both read options from this table, so
// an option is added once, as one entry, and both take it with the same name, help, checks
// and modes. Neither front end knows an option by name except through here.
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "distributed/timeline.h"
#include "lattice/cache/table_spec.h"
#include "render/render_modes.h"
#include "render/modes/scene_lattices.h"

namespace lat {

struct RenderRequest {
    std::string scene;   // the scene file (command line), for messages and --stats
    std::string output;  // the image file (command line)
    int threads = 0;
    int spp = 1;
    std::string sampler{sampler_description(kDefaultSampler).name};
    std::string stats;
    std::string mode = "exact";
    std::string lattice_dir;
    TableSpec spec;
    std::string instancing = "auto";
    TextureOptions texture;
    int shadow_map_size = 0;  // 0: the mode's own (ModeSettings::shadow_map_size)
    std::string instance_shadows = "rays";
    std::string filter = "smooth";
    std::string lod = "on";
    double lod_budget = kLodBudgetMinutes;  // of one core
    std::string footprint = "off";
    bool quiet = false;
    // Options given that cannot act in this mode, said once each (settle_request).
    std::vector<std::string> notes;

    RenderMode render_mode() const;
    LatticeFilter lattice_filter() const;
    bool footprint_on() const;
    // Whether instances are answered by lattices: tables or sub-rays (SceneLattices).
    bool answers_instances() const;
};

// Where an option's value goes: a typed field, or a function given the text of a choice.
using ChoiceSetter = std::function<void(const std::string&)>;
using OptionField = std::variant<int*, double*, std::string*, bool*, ChoiceSetter>;

// How a value is checked, in the command line's terms (the command line's messages come from
// CLI11's validators built from this; Python's from check_option_value).
struct OptionCheck {
    std::optional<std::pair<int, int>> range;  // integers, inclusive
    bool positive = false;                     // numbers > 0
    std::vector<std::string> choices;          // in sorted order, as listed in help
    // A check of the text: "" if fine, else what is expected.
    std::string (*text)(const std::string&) = nullptr;

    static OptionCheck in_range(int lo, int hi);
    static OptionCheck positive_number();
    static OptionCheck one_of(std::vector<std::string> names);
    static OptionCheck by_text(std::string (*check)(const std::string&));
};

// One option. `Target` is what it writes into: a RenderRequest, or a TableSpec for the table
// options that `rasterize` shares.
template <class Target>
struct OptionEntry {
    OptionEntry(std::string names_, std::string help_, std::function<OptionField(Target&)> field_,
                OptionCheck check_ = {}, std::vector<RenderMode> modes_ = {})
        : names(std::move(names_)), help(std::move(help_)), field(std::move(field_)),
          check(std::move(check_)), modes(std::move(modes_)) {}

    std::string names;  // CLI11 form: "--spp", "-o,--output", or "scene" (positional)
    std::string help;
    std::function<OptionField(Target&)> field;
    OptionCheck check;
    std::vector<RenderMode> modes;  // where it acts; empty: everywhere
    bool required = false;
    bool show_default = false;  // help shows the default value
    bool flag = false;          // takes no value
    bool command_line_only = false;  // files and terminal output, which Python has no use for

    // "--sigma-inv" (the long name, or the positional's); "sigma_inv" for Python.
    std::string long_name() const;
    std::string python_name() const;
};

// --sigma-inv, --encoding, --max-point-error, --max-normal-error, --dense-normals.
const std::vector<OptionEntry<TableSpec>>& table_option_entries();
// Every option of `render`, in the order of its help.
const std::vector<OptionEntry<RenderRequest>>& render_option_entries();

// Checks a value Python gave (a number or a text) against an entry's check; "" if fine, else
// "spp: 0 is not in 1 to 65536".
std::string check_option_value(const std::string& python_name, const OptionCheck& check,
                               const std::variant<long long, double, std::string>& value);

// Once the options are read: the defaults that depend on which were given (a filter needs the
// coverage encoding), then request.notes, one for each option given that cannot act here.
void settle_request(RenderRequest& request, const std::function<bool(std::string_view)>& given);

// The mode's settings for the request (progress, ranks and before_render left to the caller).
ModeSettings mode_settings(const RenderRequest& request);

// How one primitive's instances were answered, in words (summary line and stats).
std::string answer_text(const PrimitiveAnswer& p, LatticeFilter filter);
double mrays_per_s(const RenderStats& st);

// Wall-clock milestones of a render, in milliseconds from its start.
struct RenderTimings {
    double loaded = 0, written = 0;
    double loaded_cpu = 0;  // the process's CPU time (all threads) when the scene was loaded, ms
};

// A rank's timeline for the stats: {"loaded": ms, ...}, the steps it reached.
nlohmann::json timeline_json(const dist::Timeline& t);

// The figures of `render --stats` and of Python's render().
nlohmann::json render_stats_json(const RenderRequest& request, const Scene& scene,
                                 const ModeResult& r, const RenderTimings& t);

}  // namespace lat
