#include "scene/scene_loader.h"

#include <cmath>
#include <map>

#include "scene/object_parser.h"
#include "scene/scatter.h"
#include "util/error.h"
#include "util/file.h"
#include "util/hash.h"

namespace lat {
namespace {

constexpr int kMaxImageSide = 32768;
// 8192 x 8192: the float and 8-bit buffers of the largest image take about 1 GB.
constexpr std::int64_t kMaxImagePixels = std::int64_t{1} << 26;

}  // namespace

Camera parse_camera(const JsonValue& v) {
    v.allow_keys({"eye", "look_at", "up", "fov_y_deg", "width", "height"});
    Camera c;
    c.eye = v.at("eye").vec3();
    c.look_at = v.at("look_at").vec3();
    if (auto up = v.find("up")) c.up = up->direction();
    const JsonValue fov = v.at("fov_y_deg");
    c.fov_y_deg = fov.number();
    if (!(c.fov_y_deg > 0 && c.fov_y_deg < 180)) fov.fail("must be between 0 and 180 degrees");
    for (const char* key : {"width", "height"}) {
        const JsonValue s = v.at(key);
        const int n = s.integer();
        if (n < 1 || n > kMaxImageSide)
            s.fail("must be between 1 and " + std::to_string(kMaxImageSide) + " pixels");
        (key[0] == 'w' ? c.width : c.height) = n;
    }
    if (std::int64_t{c.width} * c.height > kMaxImagePixels)
        v.fail(std::to_string(c.width) + " x " + std::to_string(c.height) +
               " pixels is over the limit of " + std::to_string(kMaxImagePixels) + " pixels");
    const Vec3 w = c.look_at - c.eye;
    if (length_squared(w) == 0) v.fail("eye and look_at are the same point");
    if (!std::isfinite(length_squared(w)))
        v.fail("eye and look_at are too far apart (the distance overflows a double)");
    if (length_squared(cross(w, c.up)) <= 1e-12 * length_squared(w) * length_squared(c.up))
        v.at("up").fail("up is parallel to the viewing direction");
    return c;
}

namespace {

Material parse_material(const JsonValue& v, const std::string& name) {
    v.allow_keys({"color", "ka", "kd", "ks", "shininess"});
    Material m;
    m.name = name;
    if (auto c = v.find("color")) m.color = c->colour();
    if (auto x = v.find("ka")) m.ka = x->non_negative();
    if (auto x = v.find("kd")) m.kd = x->non_negative();
    if (auto x = v.find("ks")) m.ks = x->non_negative();
    if (auto x = v.find("shininess")) m.shininess = x->non_negative();
    return m;
}

}  // namespace

namespace {

std::shared_ptr<const Shape> parse_chain(const JsonValue& v) {
    std::vector<ChainSphere> spheres;
    const JsonValue sv = v.at("spheres");
    if (sv.size() == 0) sv.fail("a primitive needs at least one sphere");
    for (std::size_t i = 0; i < sv.size(); ++i) {
        const JsonValue s = sv[i];
        if (!s.is_array() || s.size() != 4) s.fail("expected [x, y, z, radius]");
        spheres.push_back({{s[0].number(), s[1].number(), s[2].number()}, s[3].positive()});
    }
    std::vector<ChainCylinder> cylinders;
    if (auto cv = v.find("cylinders")) {
        for (std::size_t i = 0; i < cv->size(); ++i) {
            const JsonValue c = (*cv)[i];
            if (!c.is_array() || c.size() != 3) c.fail("expected [sphere_i, sphere_j, radius]");
            const int a = c[0].integer(), b = c[1].integer();
            for (int k = 0; k < 2; ++k) {
                const int idx = k == 0 ? a : b;
                if (idx < 0 || idx >= static_cast<int>(spheres.size()))
                    c[static_cast<std::size_t>(k)].fail(
                        "sphere index " + std::to_string(idx) + " does not exist (the primitive has " +
                        std::to_string(spheres.size()) + " spheres, numbered from 0)");
            }
            if (length_squared(spheres[static_cast<std::size_t>(a)].center -
                               spheres[static_cast<std::size_t>(b)].center) == 0)
                c.fail("the cylinder's two spheres have the same centre");
            cylinders.push_back({a, b, c[2].positive()});
        }
    }
    return std::make_shared<ChainShape>(std::move(spheres), std::move(cylinders));
}

}  // namespace

Primitive parse_primitive(const JsonValue& v, const std::string& name, const ObjectParser* objects) {
    v.allow_keys({"spheres", "cylinders", "object", "lattice"});
    Primitive p;
    p.name = name;
    p.where = v.path();
    Fingerprint fp;
    if (auto obj = v.find("object")) {
        if (v.has("spheres") || v.has("cylinders"))
            v.fail("a primitive is either spheres and cylinders or an object, not both");
        if (!objects) obj->fail("objects are not allowed as primitives here");
        p.shape = objects->parse_shape(*obj);
        p.definition = nlohmann::json{{"object", obj->raw()}}.dump();
        fp.add("object").add(obj->raw().dump());
    } else {
        p.shape = parse_chain(v);
        fp.add("chain").add(v.at("spheres").raw().dump());
        nlohmann::json def{{"spheres", v.at("spheres").raw()}};
        if (auto c = v.find("cylinders")) {
            fp.add(c->raw().dump());
            def["cylinders"] = c->raw();
        }
        p.definition = def.dump();
    }
    p.fingerprint = fp.value();
    if (auto lv = v.find("lattice")) {
        lv->allow_keys({"sigma", "cells"});
        LatticeSpec spec;
        spec.sigma = lv->at("sigma").positive();
        const JsonValue cells = lv->at("cells");
        if (!cells.is_array() || cells.size() != 3) cells.fail("expected [nx, ny, nz]");
        for (std::size_t a = 0; a < 3; ++a) {
            const int n = cells[a].integer();
            if (n < 1 || n > 4096) cells[a].fail("cell counts must be between 1 and 4096");
            spec.cells[a] = n;
        }
        p.lattice = spec;
    }
    return p;
}

namespace {

std::optional<std::string> name_of(const JsonValue& v) {
    if (!v.is_object()) return std::nullopt;
    if (auto n = v.find("name")) return n->string();
    return std::nullopt;
}

// The surface a scatter covers: an object given inline (drawn too), or another object of the
// list named by "name" or by index.
JsonValue scatter_target(const JsonValue& sc, const JsonValue& objects,
                         const std::map<std::string, std::size_t>& names,
                         const ObjectParser& parser, Scene& s) {
    const JsonValue on = sc.at("on");
    if (on.is_object()) {
        if (on.has("type") && on.at("type").is_string() && on.at("type").string() == "scatter")
            on.fail("a scatter cannot cover another scatter");
        s.objects.push_back(parser.parse(on));
        return on;
    }
    if (on.is_string()) {
        auto it = names.find(on.string());
        if (it == names.end()) on.fail("no object is named '" + on.string() + "'");
        return objects[it->second];
    }
    const int i = on.integer();
    if (i < 0 || static_cast<std::size_t>(i) >= objects.size())
        on.fail("object index " + std::to_string(i) + " does not exist (there are " +
                std::to_string(objects.size()) + " objects, numbered from 0)");
    const JsonValue target = objects[static_cast<std::size_t>(i)];
    if (target.at("type").string() == "scatter") on.fail("a scatter cannot cover another scatter");
    return target;
}

// Objects first, then scatters (which may name objects anywhere in the list) expanded into
// groups of instances numbered after them (an inline surface of a scatter is an object).
void load_objects(const JsonValue& objects, const ObjectParser& parser, Scene& s, bool progress) {
    std::map<std::string, std::size_t> names;
    std::vector<std::size_t> scatters;
    for (std::size_t i = 0; i < objects.size(); ++i) {
        const JsonValue o = objects[i];
        if (auto n = name_of(o)) {
            if (!names.emplace(*n, i).second) o.at("name").fail("another object is named '" + *n + "'");
        }
        if (o.is_object() && o.has("type") && o.at("type").is_string() &&
            o.at("type").string() == "scatter") {
            scatters.push_back(i);
            continue;
        }
        s.objects.push_back(parser.parse(o));
    }
    for (const std::size_t i : scatters) {
        const JsonValue sc = objects[i];
        const JsonValue on = scatter_target(sc, objects, names, parser, s);
        ScatterGroup& g = s.scatters.emplace_back();
        g.name = name_of(sc).value_or("");
        g.json_index = i;
        expand_scatter(sc, on, parser, s.primitives, s.object_count(), g, progress);
    }
    s.number_scatters();
}

}  // namespace

Scene load_scene_text(const std::string& text, const std::string& file, bool progress) {
    const nlohmann::json doc = parse_json_text(text, file);
    const JsonValue root(doc, "", file);
    if (!root.is_object()) root.fail("a scene file must hold a JSON object");
    root.allow_keys({"format", "camera", "background", "ambient", "shadows", "lights",
                     "materials", "primitives", "objects"});
    Scene s;
    s.file = file;
    if (auto f = root.find("format")) {
        s.format = f->string();
        if (s.format != "lattice-reference/1" && s.format != "lattice/1")
            f->fail("unknown format '" + s.format + "' (expected lattice/1 or lattice-reference/1)");
    }
    s.camera = parse_camera(root.at("camera"));
    if (auto b = root.find("background")) s.background = b->colour();
    if (auto a = root.find("ambient")) s.ambient = a->colour();
    if (auto sh = root.find("shadows")) s.shadows = sh->boolean();
    if (auto lights = root.find("lights")) {
        for (std::size_t i = 0; i < lights->size(); ++i) {
            const JsonValue l = (*lights)[i];
            l.allow_keys({"position", "intensity"});
            PointLight pl;
            pl.position = l.at("position").vec3();
            if (auto in = l.find("intensity")) pl.intensity = in->colour();
            s.lights.push_back(pl);
        }
    }
    std::map<std::string, std::uint32_t> material_index;
    if (auto mats = root.find("materials")) {
        if (!mats->is_object()) mats->fail("expected an object of named materials");
        for (const std::string& name : mats->keys()) {
            material_index[name] = static_cast<std::uint32_t>(s.materials.size());
            s.materials.push_back(parse_material(mats->at(name), name));
        }
    }
    const ObjectParser parser(material_index, s.primitives);
    if (auto prims = root.find("primitives")) {
        if (!prims->is_object()) prims->fail("expected an object of named primitives");
        for (const std::string& name : prims->keys())
            s.primitives.push_back(parse_primitive(prims->at(name), name, &parser));
    }
    load_objects(root.at("objects"), parser, s, progress);
    return s;
}

const Primitive& find_primitive(const Scene& scene, const std::string& name) {
    std::string known;
    for (const Primitive& p : scene.primitives) {
        if (p.name == name) return p;
        known += (known.empty() ? "" : ", ") + p.name;
    }
    throw InputError(scene.file + ": no primitive named '" + name + "'" +
                     (known.empty() ? " (the scene defines none)" : " (it has: " + known + ")"));
}

Scene load_scene(const std::string& path, bool progress) {
    return load_scene_text(read_text_file(path, "scene file"), path, progress);
}

}  // namespace lat
