// lattice.Scene, lattice.load and lattice.scatters: scenes through the same loader, and the same
// checks, as files; their scatters' placements as arrays.
#include <chrono>
#include <pybind11/stl.h>

#include "bindings.h"
#include "scene/scatter.h"
#include "scene/scene_loader.h"
#include "scene_object.h"

namespace lat::py {
namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

std::string json_text(const pyb::object& value) {
    return pyb::module_::import("json").attr("dumps")(value).cast<std::string>();
}

std::shared_ptr<PyScene> scene_from_text(const std::string& text, const std::string& name) {
    const auto start = std::chrono::steady_clock::now();
    auto s = std::make_shared<PyScene>();
    s->scene = load_scene_text(text, name);
    s->load_ms = ms_since(start);
    return s;
}

pyb::list vec(const Vec3& v) { return pyb::cast(std::vector<double>{v.x, v.y, v.z}); }

pyb::dict camera_dict(const Camera& c) {
    pyb::dict d;
    d["eye"] = vec(c.eye);
    d["look_at"] = vec(c.look_at);
    d["up"] = vec(c.up);
    d["fov_y_deg"] = c.fov_y_deg;
    d["width"] = c.width;
    d["height"] = c.height;
    return d;
}

// The camera from a dict, checked as the loader checks a file's "camera".
void set_camera(PyScene& s, const pyb::dict& d) {
    const nlohmann::json j = nlohmann::json::parse(json_text(d));
    s.scene.camera = parse_camera(JsonValue(j, "camera", s.scene.file));
}

// Each scatter's instances: where they stand, their frames and sizes.
pyb::list scatters(const PyScene& s) {
    pyb::list out;
    for (const ScatterGroup& g : s.scene.scatters) {
        const auto n = static_cast<pyb::ssize_t>(g.count);
        pyb::array_t<double> roots({n, pyb::ssize_t{3}}), frames({n, pyb::ssize_t{3}, pyb::ssize_t{3}}), scales(n);
        double *r = roots.mutable_data(), *f = frames.mutable_data(), *sc = scales.mutable_data();
        const Primitive& prim = s.scene.primitives[static_cast<std::size_t>(g.primitive)];
        for (std::size_t i = 0; i < g.count; ++i) {
            const Affine& a = g.placements[i];
            const Mat3& m = a.m;
            const double scale = std::cbrt(std::abs(determinant(m)));
            const Vec3 root = a.point(primitive_root(prim));
            for (int c = 0; c < 3; ++c) {
                r[3 * i + c] = root[c];
                for (int k = 0; k < 3; ++k) f[9 * i + 3 * c + k] = m.r[c][k] / scale;
            }
            sc[i] = scale;
        }
        pyb::dict d;
        d["name"] = g.name;
        d["object"] = g.json_index;
        d["primitive"] = prim.name;
        d["roots"] = roots;
        d["frames"] = frames;
        d["scales"] = scales;
        out.append(d);
    }
    return out;
}

}  // namespace

void bind_scene(pyb::module_& m) {
    pyb::class_<PyScene, std::shared_ptr<PyScene>>(m, "Scene", R"(A scene, loaded and checked.

Scene(d, path=None): from a dict shaped as a scene file (docs/scene-format.md). `path`
names it in messages and is where relative mesh and table paths start (default: "scene",
relative paths from the working directory). A mistake raises InputError naming the place,
e.g. "scene: objects[3].transform: ...".)")
        .def(pyb::init([](const pyb::dict& d, std::optional<std::string> path) {
                 return scene_from_text(json_text(d), path.value_or("scene"));
             }),
             pyb::arg("d"), pyb::arg("path") = pyb::none())
        .def_property_readonly("path", [](const PyScene& s) { return s.scene.file; })
        .def_property_readonly("load_ms", [](const PyScene& s) { return s.load_ms; })
        .def_property_readonly("width", [](const PyScene& s) { return s.scene.camera.width; })
        .def_property_readonly("height", [](const PyScene& s) { return s.scene.camera.height; })
        .def_property_readonly("object_count", [](const PyScene& s) { return s.scene.object_count(); })
        .def_property_readonly("primitives", [](const PyScene& s) {
            std::vector<std::string> names;
            for (const Primitive& p : s.scene.primitives) names.push_back(p.name);
            return names;
        })
        .def_property("camera", [](const PyScene& s) { return camera_dict(s.scene.camera); }, &set_camera,
                      "The camera as a dict; assigning a dict (e.g. dict(s.camera, width=128)) checks "
                      "it as the loader does, and keeps the meshes and objects loaded")
        .def_property(
            "shadows", [](const PyScene& s) { return s.scene.shadows; },
            [](PyScene& s, bool on) { s.scene.shadows = on; })
        .def("copy", [](const PyScene& s) { return std::make_shared<PyScene>(s); },
             "A copy to edit; shapes and meshes are shared, not reloaded")
        .def("__repr__", [](const PyScene& s) {
            return "<lattice.Scene " + s.scene.file + ": " + std::to_string(s.scene.camera.width) + "x" +
                   std::to_string(s.scene.camera.height) + ", " + std::to_string(s.scene.object_count()) +
                   " objects>";
        });

    m.def(
        "load",
        [](const std::string& path) {
            const auto start = std::chrono::steady_clock::now();
            auto s = std::make_shared<PyScene>();
            s->scene = load_scene(path);
            s->load_ms = ms_since(start);
            return s;
        },
        pyb::arg("path"), "Loads a scene file (JSON), as `lattice render` does; InputError names the place");
    m.def("scatters", &scatters, pyb::arg("scene"), R"(The scene's scatter objects' instances as arrays.

A list, one dict per scatter: name, object (its index in the file's objects), primitive,
roots (N x 3: where each instance's root, the bottom centre of its lattice box, stands),
frames (N x 3 x 3: the instance's axes as columns, unit length), scales (N).)");
}

}  // namespace lat::py
