// lattice scatter SCENE.json [--object NAME] -o placed.json: a scatter expanded into explicit
// instance objects, for other tools. The output is the scene itself with that scatter replaced
// by its instances (appended at the end of "objects"; an inline "on" object takes the
// scatter's place), so it renders the same image.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "common.h"
#include "scene/json_reader.h"
#include "scene/scene_loader.h"
#include "util/error.h"

namespace lat::cli {
namespace {

namespace fs = std::filesystem;

struct ScatterArgs {
    std::string scene;
    std::string object;
    std::string output;
};

const ScatterGroup& find_group(const Scene& s, const std::string& name) {
    std::string known;
    for (const ScatterGroup& g : s.scatters) {
        if (g.name == name || (name.empty() && s.scatters.size() == 1)) return g;
        known += (known.empty() ? "" : ", ") + (g.name.empty() ? "objects[" + std::to_string(g.json_index) + "]" : g.name);
    }
    if (s.scatters.empty()) throw InputError(located_message(s.file, "objects", "the scene has no scatter objects"));
    throw InputError(located_message(
        s.file, "objects",
        name.empty() ? "the scene has several scatters: choose one with --object (" + known + ")"
                     : "no scatter is named '" + name + "' (scatters: " + known + ")"));
}

nlohmann::json matrix(const Transform& xf) {
    const Affine& a = xf.forward();
    nlohmann::json rows = nlohmann::json::array();
    for (std::size_t r = 0; r < 3; ++r)
        rows.push_back({a.m.r[r].x, a.m.r[r].y, a.m.r[r].z, a.t[r]});
    return rows;
}

// The folder a file named on the command line is in: "." for a bare name ("placed.json"), whose
// parent_path() is empty and has no absolute form.
fs::path folder_of(const std::string& file) {
    const fs::path parent = fs::path(file).parent_path();
    return parent.empty() ? fs::path(".") : parent;
}

// Mesh files are named relative to the scene file: keep them found from the output's folder
// (by their absolute path when no relative one leads there).
void move_mesh_paths(nlohmann::json& j, const fs::path& from, const fs::path& to) {
    if (j.is_array()) {
        for (auto& x : j) move_mesh_paths(x, from, to);
    } else if (j.is_object()) {
        if (j.value("type", "") == "mesh" && j.contains("file") && j["file"].is_string()) {
            const fs::path f = j["file"].get<std::string>();
            if (f.is_relative()) {
                std::error_code ec;
                const fs::path target = fs::absolute(from / f, ec).lexically_normal();
                const fs::path moved = fs::relative(target, fs::absolute(to, ec), ec);
                j["file"] = (ec || moved.empty() ? target : moved).string();
            }
        }
        for (auto& [k, v] : j.items()) move_mesh_paths(v, from, to);
    }
}

int run_scatter(const ScatterArgs& a) {
    const Scene s = load_scene(a.scene);
    const ScatterGroup& g = find_group(s, a.object);
    nlohmann::json doc = parse_json_file(a.scene);
    nlohmann::json& objects = doc["objects"];
    const nlohmann::json scatter = objects[g.json_index];
    const std::string primitive = scatter["primitive"].get<std::string>();
    const std::string material = scatter["material"].get<std::string>();
    if (scatter["on"].is_object()) {
        objects[g.json_index] = scatter["on"];
    } else {
        objects.erase(g.json_index);
        for (auto& o : objects)  // later objects moved down by one
            if (o.value("type", "") == "scatter" && o["on"].is_number_integer() &&
                o["on"].get<long>() > static_cast<long>(g.json_index))
                o["on"] = o["on"].get<long>() - 1;
    }
    for (std::size_t i = g.first; i < g.first + g.count; ++i)
        objects.push_back({{"type", "instance"}, {"primitive", primitive}, {"material", material},
                           {"transform", matrix(s.transform(i))}});
    move_mesh_paths(doc, folder_of(a.scene), folder_of(a.output));
    write_json_file(a.output, doc);
    std::printf("%s: %zu instances of '%s'\n", a.output.c_str(), g.count, primitive.c_str());
    return 0;
}

}  // namespace

Command add_scatter_command(CLI::App& parent) {
    auto args = std::make_shared<ScatterArgs>();
    Command c;
    c.app = parent.add_subcommand(
        "scatter", "Expand a scatter object into explicit instances (a scene that renders the same)");
    c.app->add_option("scene", args->scene, "Scene file")->required();
    c.app->add_option("--object", args->object, "The scatter's name (needed when there are several)");
    c.app->add_option("-o,--output", args->output, "The scene written, with explicit instances")->required();
    c.run = [args] { return run_scatter(*args); };
    return c;
}

}  // namespace lat::cli
