#include "common.h"


#include <CLI/CLI.hpp>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>

#include "lattice/cache/table_spec.h"
#include "distributed/job.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/file.h"
#include "util/hash.h"

namespace lat::cli {

const std::map<std::string, LatticeFilter>& lattice_filters() {
    static const std::map<std::string, LatticeFilter> filters = [] {
        std::map<std::string, LatticeFilter> m;
        for (const auto& [name, value] : kLatticeFilterNames) m.emplace(name, value);
        return m;
    }();
    return filters;
}

namespace {

// What an entry's field is, as a CLI11 option: a flag, a choice handed to a setter, or a value.
template <class Target>
CLI::Option* add_field(CLI::App& app, const OptionEntry<Target>& e, Target& target) {
    const OptionField field = e.field(target);
    if (bool* const* flag = std::get_if<bool*>(&field)) return app.add_flag(e.names, **flag, e.help);
    if (const ChoiceSetter* set = std::get_if<ChoiceSetter>(&field))
        return app.add_option_function<std::string>(e.names, *set, e.help);
    return std::visit(
        [&](auto value) -> CLI::Option* {
            if constexpr (std::is_pointer_v<decltype(value)>) return app.add_option(e.names, *value, e.help);
            return nullptr;  // handled above
        },
        field);
}

}  // namespace

template <class Target>
void add_entries(CLI::App& app, const std::vector<OptionEntry<Target>>& entries, Target& target) {
    for (const OptionEntry<Target>& e : entries) {
        CLI::Option* o = add_field(app, e, target);
        if (e.required) o->required();
        if (e.check.range) o->check(CLI::Range(e.check.range->first, e.check.range->second));
        if (e.check.positive) o->check(CLI::PositiveNumber);
        if (!e.check.choices.empty()) o->check(CLI::IsMember(e.check.choices));
        if (e.check.text) o->check(e.check.text);
        if (e.show_default) o->capture_default_str();
    }
}
template void add_entries(CLI::App&, const std::vector<OptionEntry<TableSpec>>&, TableSpec&);
template void add_entries(CLI::App&, const std::vector<OptionEntry<RenderRequest>>&, RenderRequest&);

void add_table_options(CLI::App& app, TableSpec& spec) {
    add_entries(app, table_option_entries(), spec);
}

void agree_on_scene(const std::string& scene_file) {
    if (!dist::distributed()) return;
    std::string bytes;
    dist::agree([&] { bytes = read_text_file(scene_file, "scene file"); });
    dist::agree_on(hash_bytes(bytes.data(), bytes.size()), scene_file + ": the scene file");
}

void write_json_file(const std::string& path, const nlohmann::json& j) {
    AtomicFile out(path);  // a unique temporary: concurrent writers of one path never collide
    const std::string text = j.dump(2) + "\n";
    out.write(text.data(), text.size());
    out.commit();
}

}  // namespace lat::cli
