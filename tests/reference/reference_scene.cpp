// Reading "lattice-reference/1" scene files for the reference tracer, with nlohmann/json only.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "reference_tracer.h"

namespace reftrace {
namespace {

using nlohmann::json;
constexpr Real kInf = std::numeric_limits<Real>::infinity();

[[noreturn]] void fail(const std::string& where, const std::string& what) {
    throw std::runtime_error(where + ": " + what);
}

const json& member(const json& j, const char* key, const std::string& where) {
    if (!j.is_object() || !j.contains(key)) fail(where, std::string("missing \"") + key + "\"");
    return j[key];
}

Real number(const json& j, const std::string& where) {
    if (!j.is_number()) fail(where, "expected a number");
    // Through the text's double: the file holds decimal numbers, and the project reads doubles
    // too, so both start from the same values.
    return static_cast<Real>(j.get<double>());
}

Real number(const json& j, const char* key, const std::string& where) {
    return number(member(j, key, where), where + "." + key);
}

Vec vec3(const json& j, const std::string& where) {
    if (!j.is_array() || j.size() != 3) fail(where, "expected [x, y, z]");
    return {number(j[0], where), number(j[1], where), number(j[2], where)};
}

Vec vec3(const json& j, const char* key, const std::string& where) {
    return vec3(member(j, key, where), where + "." + key);
}

Real norm(const Vec& v) {
    return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
}

Primitive parse_primitive(const json& j, const std::string& where) {
    Primitive p;
    std::vector<Ball> centres;
    for (const json& s : member(j, "spheres", where)) {
        if (!s.is_array() || s.size() != 4) fail(where + ".spheres", "expected [x, y, z, r]");
        p.balls.push_back(
            {{number(s[0], where), number(s[1], where), number(s[2], where)}, number(s[3], where)});
    }
    for (const json& c : member(j, "cylinders", where)) {
        if (!c.is_array() || c.size() != 3) fail(where + ".cylinders", "expected [i, j, r]");
        const auto i = c[0].get<std::size_t>(), k = c[1].get<std::size_t>();
        if (i >= p.balls.size() || k >= p.balls.size()) fail(where, "cylinder sphere index");
        const Vec a = p.balls[i].c, b = p.balls[k].c;
        const Vec d{b.x - a.x, b.y - a.y, b.z - a.z};
        const Real len = norm(d);
        if (!(len > 0)) fail(where, "cylinder of zero length");
        p.cylinders.push_back({a, {d.x / len, d.y / len, d.z / len}, len, number(c[2], where)});
    }
    // A box around the balls and the cylinders (whose ends lie within r of their axis ends).
    Real lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
    auto grow = [&](const Vec& c, Real r) {
        const Real v[3] = {c.x, c.y, c.z};
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], v[k] - r);
            hi[k] = std::max(hi[k], v[k] + r);
        }
    };
    for (const Ball& b : p.balls) grow(b.c, b.r);
    for (const Cylinder& c : p.cylinders) {
        grow(c.a, c.r);
        grow(
            {c.a.x + c.length * c.axis.x, c.a.y + c.length * c.axis.y, c.a.z + c.length * c.axis.z},
            c.r);
    }
    p.lo = {lo[0], lo[1], lo[2]};
    p.hi = {hi[0], hi[1], hi[2]};
    return p;
}

void invert3(const Real m[3][3], Real out[3][3], const std::string& where) {
    const Real det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if (!(std::fabs(det) > 0)) fail(where, "singular transform");
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
            // Cofactor of m[c][r] (transposed) over the determinant.
            const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
            out[r][c] = (m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]) / det;
        }
    }
}

// The world box of an instance: the primitive's box with its 8 corners mapped.
void instance_box(Object& o, const Primitive& p) {
    Real lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
    const Real t[3] = {o.t.x, o.t.y, o.t.z};
    for (int corner = 0; corner < 8; ++corner) {
        const Real x[3] = {corner & 1 ? p.hi.x : p.lo.x, corner & 2 ? p.hi.y : p.lo.y,
                           corner & 4 ? p.hi.z : p.lo.z};
        for (int r = 0; r < 3; ++r) {
            const Real w = o.m[r][0] * x[0] + o.m[r][1] * x[1] + o.m[r][2] * x[2] + t[r];
            lo[r] = std::min(lo[r], w);
            hi[r] = std::max(hi[r], w);
        }
    }
    // A hair's breadth of slack, so that rounding in the mapping never culls a true hit.
    const Real pad = 1e-9L * (1 + std::max({std::fabs(lo[0]), std::fabs(hi[0]), std::fabs(lo[1]),
                                            std::fabs(hi[1]), std::fabs(lo[2]), std::fabs(hi[2])}));
    o.lo = {lo[0] - pad, lo[1] - pad, lo[2] - pad};
    o.hi = {hi[0] + pad, hi[1] + pad, hi[2] + pad};
}

}  // namespace

Scene parse_scene(const std::string& json_text, const std::string& name) {
    json j;
    try {
        j = json::parse(json_text);
    } catch (const json::exception& e) {
        fail(name, e.what());
    }
    const json& format = member(j, "format", name);
    if (format != "lattice-reference/1") fail(name, "format is not \"lattice-reference/1\"");

    Scene s;
    const json& cam = member(j, "camera", name);
    const std::string cw = name + ".camera";
    s.camera.eye = vec3(cam, "eye", cw);
    s.camera.look_at = vec3(cam, "look_at", cw);
    s.camera.up = vec3(cam, "up", cw);
    s.camera.fov_y_deg = number(cam, "fov_y_deg", cw);
    s.camera.width = member(cam, "width", cw).get<int>();
    s.camera.height = member(cam, "height", cw).get<int>();
    if (s.camera.width <= 0 || s.camera.height <= 0) fail(cw, "image size must be positive");
    s.background = vec3(j, "background", name);
    s.ambient = vec3(j, "ambient", name);
    s.shadows = member(j, "shadows", name).get<bool>();
    for (const json& l : member(j, "lights", name)) {
        s.lights.push_back(
            {vec3(l, "position", name + ".lights"), vec3(l, "intensity", name + ".lights")});
    }

    std::map<std::string, int> material_index, primitive_index;
    for (const auto& [key, m] : member(j, "materials", name).items()) {
        const std::string w = name + ".materials." + key;
        material_index[key] = static_cast<int>(s.materials.size());
        s.materials.push_back({vec3(m, "color", w), number(m, "ka", w), number(m, "kd", w),
                               number(m, "ks", w), number(m, "shininess", w)});
    }
    if (j.contains("primitives")) {
        for (const auto& [key, p] : j["primitives"].items()) {
            primitive_index[key] = static_cast<int>(s.primitives.size());
            s.primitives.push_back(parse_primitive(p, name + ".primitives." + key));
        }
    }

    const json& objects = member(j, "objects", name);
    for (std::size_t k = 0; k < objects.size(); ++k) {
        const json& oj = objects[k];
        const std::string w = name + ".objects[" + std::to_string(k) + "]";
        Object o;
        const std::string mat = member(oj, "material", w).get<std::string>();
        if (!material_index.count(mat)) fail(w, "unknown material \"" + mat + "\"");
        o.material = material_index[mat];
        const std::string type = member(oj, "type", w).get<std::string>();
        if (type == "sphere") {
            o.kind = Kind::sphere;
            o.ball = {vec3(oj, "center", w), number(oj, "radius", w)};
        } else if (type == "halfspace") {
            o.kind = Kind::halfspace;
            o.point = vec3(oj, "point", w);
            const Vec n = vec3(oj, "normal", w);
            const Real len = norm(n);
            if (!(len > 0)) fail(w, "zero normal");
            o.normal = {n.x / len, n.y / len, n.z / len};
        } else if (type == "instance") {
            o.kind = Kind::instance;
            const std::string prim = member(oj, "primitive", w).get<std::string>();
            if (!primitive_index.count(prim)) fail(w, "unknown primitive \"" + prim + "\"");
            o.primitive = primitive_index[prim];
            const json& xf = member(oj, "transform", w);
            if (!xf.is_array() || xf.size() != 3) fail(w, "transform must be 3 rows of 4");
            Real t[3];
            for (int r = 0; r < 3; ++r) {
                if (!xf[r].is_array() || xf[r].size() != 4) fail(w, "transform rows need 4");
                for (int c = 0; c < 3; ++c) o.m[r][c] = number(xf[r][c], w + ".transform");
                t[r] = number(xf[r][3], w + ".transform");
            }
            o.t = {t[0], t[1], t[2]};
            invert3(o.m, o.minv, w);
            instance_box(o, s.primitives[o.primitive]);
        } else {
            fail(w, "unknown type \"" + type + "\"");
        }
        s.objects.push_back(o);
    }
    return s;
}

Scene load_scene(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error(path + ": cannot open");
    std::stringstream text;
    text << in.rdbuf();
    return parse_scene(text.str(), path);
}

}  // namespace reftrace
