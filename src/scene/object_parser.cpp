#include "scene/object_parser.h"

#include <cmath>
#include <filesystem>

#include "geometry/named_shapes.h"
#include "io/mesh_file.h"
#include "util/error.h"
#include "geometry/polynomial_parser.h"
#include "scene/scene_loader.h"

namespace lat {
namespace {

const char* const kTypes =
    "sphere, ellipsoid, halfspace, cylinder, cone, paraboloid, hyperboloid1, hyperboloid2, "
    "torus, quartic, mesh, instance, csg, scatter";

Poly3 parse_quartic_polynomial(const JsonValue& v) {
    const bool text = v.has("polynomial"), coefs = v.has("coefficients");
    if (text == coefs) v.fail("a quartic needs exactly one of 'polynomial' or 'coefficients'");
    if (coefs) {
        const JsonValue list = v.at("coefficients");
        Poly3 f;
        for (std::size_t n = 0; n < list.size(); ++n) {
            const JsonValue term = list[n];
            if (!term.is_array() || term.size() != 4) term.fail("expected [i, j, k, a] for a * x^i y^j z^k");
            const int i = term[0].integer(), j = term[1].integer(), k = term[2].integer();
            if (i < 0 || j < 0 || k < 0) term.fail("exponents must not be negative");
            if (i + j + k > 4) term.fail("degree " + std::to_string(i + j + k) + " is over 4");
            f.at(i, j, k) += term[3].number();
            if (!std::isfinite(f.at(i, j, k)))
                term.fail("the coefficients of x^" + std::to_string(i) + " y^" + std::to_string(j) +
                          " z^" + std::to_string(k) + " add up beyond the range of a double");
        }
        if (f.degree() < 1) list.fail("the polynomial has no term in x, y or z");
        return f;
    }
    if (v.has("constants") && !v.at("constants").is_object())
        v.at("constants").fail("expected an object of named numbers");
    std::map<std::string, double> constants;
    if (auto c = v.find("constants"))
        for (const std::string& k : c->keys()) constants[k] = c->at(k).number();
    const JsonValue p = v.at("polynomial");
    try {
        const Poly3 f = parse_polynomial(p.string(), constants);
        if (f.degree() < 1) p.fail("the polynomial has no term in x, y or z");
        return f;
    } catch (const PolynomialParseError& e) {
        p.fail("column " + std::to_string(e.column()) + ": " + e.what());
    }
}

Vec3 axis_or_z(const JsonValue& v) {
    auto a = v.find("axis");
    return a ? normalize(a->direction()) : Vec3{0, 0, 1};
}

Vec3 positive_vec3(const JsonValue& v) {
    const Vec3 r = v.vec3();
    if (!(r.x > 0 && r.y > 0 && r.z > 0)) v.fail("all three must be positive");
    return r;
}

}  // namespace

ObjectParser::ObjectParser(const std::map<std::string, std::uint32_t>& materials,
                           const std::vector<Primitive>& primitives)
    : materials_(materials), primitives_(primitives) {}

std::uint32_t ObjectParser::material(const JsonValue& v) const {
    const std::string name = v.string();
    auto it = materials_.find(name);
    if (it == materials_.end()) {
        std::string known;
        for (const auto& [k, i] : materials_) known += (known.empty() ? "" : ", ") + k;
        v.fail("unknown material '" + name + "'" +
               (known.empty() ? " (the scene defines no materials)" : " (known: " + known + ")"));
    }
    return it->second;
}

ObjectParser::Leaf ObjectParser::parse_leaf(const JsonValue& v, const std::string& type) const {
    auto keys = [&](std::initializer_list<const char*> extra) {
        std::vector<const char*> all{"type", "name", "material", "transform"};
        all.insert(all.end(), extra.begin(), extra.end());
        v.allow_keys(all, (type[0] == 'e' || type[0] == 'i' ? "an " : "a ") + type);
    };
    auto placed = [](PlacedShape p) { return Leaf{std::move(p.shape), p.placement, -1}; };

    if (type == "sphere") {
        keys({"center", "radius"});
        return placed(make_sphere(v.vec3_or("center", {}), v.at("radius").positive()));
    }
    if (type == "ellipsoid") {
        keys({"center", "radii"});
        return placed(make_ellipsoid(v.vec3_or("center", {}), positive_vec3(v.at("radii"))));
    }
    if (type == "halfspace") {
        keys({"point", "normal"});
        return placed(make_halfspace(v.vec3_or("point", {}), v.at("normal").direction()));
    }
    if (type == "cylinder") {
        keys({"center", "axis", "radius"});
        const double r = v.at("radius").positive();
        return placed(make_cylinder(v.vec3_or("center", {}), axis_or_z(v), r, r));
    }
    if (type == "cone") {
        keys({"apex", "axis", "half_angle_deg"});
        const JsonValue a = v.at("half_angle_deg");
        const double deg = a.number();
        if (!(deg > 0 && deg < 90)) a.fail("must be between 0 and 90 degrees (exclusive)");
        const double k = std::tan(deg * M_PI / 180.0);
        return placed(make_cone(v.vec3_or("apex", {}), axis_or_z(v), k, k));
    }
    if (type == "paraboloid") {
        keys({"vertex", "axis", "radius", "height"});
        // Radius r at height h: x² + y² = (r²/h) z.
        const double r = v.at("radius").positive();
        double h = 1.0;
        if (auto hv = v.find("height")) h = hv->positive();
        const double a = r / std::sqrt(h);
        return placed(make_paraboloid(v.vec3_or("vertex", {}), axis_or_z(v), a, a));
    }
    if (type == "hyperboloid1" || type == "hyperboloid2") {
        keys({"center", "axis", "radii"});
        const Vec3 r = positive_vec3(v.at("radii"));
        const Vec3 c = v.vec3_or("center", {});
        return placed(type == "hyperboloid1" ? make_hyperboloid1(c, axis_or_z(v), r)
                                             : make_hyperboloid2(c, axis_or_z(v), r));
    }
    if (type == "torus") {
        keys({"center", "axis", "major_radius", "minor_radius"});
        const double R = v.at("major_radius").positive();
        const double r = v.at("minor_radius").positive();
        return placed(make_torus(v.vec3_or("center", {}), axis_or_z(v), R, r));
    }
    if (type == "quartic") {
        keys({"polynomial", "constants", "coefficients"});
        return placed(make_algebraic(parse_quartic_polynomial(v), Bounds3::infinite()));
    }
    if (type == "mesh") {
        keys({"file", "smooth"});
        std::shared_ptr<const TriangleMeshShape> m = mesh(v);
        const bool closed = m->closed();
        return {std::move(m), Transform{}, -1, closed};
    }
    if (type == "instance") {
        keys({"primitive"});
        const JsonValue p = v.at("primitive");
        const std::string name = p.string();
        for (std::size_t i = 0; i < primitives_.size(); ++i)
            if (primitives_[i].name == name)
                return {primitives_[i].shape, Transform{}, static_cast<int>(i)};
        std::string known;
        for (const Primitive& q : primitives_) known += (known.empty() ? "" : ", ") + q.name;
        p.fail("unknown primitive '" + name + "'" +
               (known.empty() ? " (the scene defines no primitives)" : " (known: " + known + ")"));
    }
    v.at("type").fail("unknown object type '" + type + "' (expected one of: " + kTypes + ")");
}

int ObjectParser::add_csg(CsgShape& csg, const JsonValue& v, const Transform& to_root,
                          std::optional<std::uint32_t> override_material, int depth) const {
    if (depth > kMaxCsgDepth)
        v.fail("csg tree nested deeper than " + std::to_string(kMaxCsgDepth) + " levels");
    if (!v.is_object()) v.fail("expected an object");
    const std::string type = v.at("type").string();
    Transform xf = to_root;
    if (auto t = v.find("transform")) xf = to_root * parse_transform(*t);

    if (type == "csg") {
        v.allow_keys({"type", "name", "op", "children", "material", "transform"});
        if (!override_material)
            if (auto m = v.find("material")) override_material = material(*m);
        const JsonValue opv = v.at("op");
        const std::string op = opv.string();
        CsgOp cop;
        if (op == "union") cop = CsgOp::kUnion;
        else if (op == "intersection") cop = CsgOp::kIntersection;
        else if (op == "difference") cop = CsgOp::kDifference;
        else opv.fail("unknown operation '" + op + "' (expected union, intersection or difference)");
        const JsonValue children = v.at("children");
        if (children.size() == 0) children.fail("a csg node needs at least one child");
        if (cop == CsgOp::kDifference && children.size() < 2)
            children.fail("a difference needs at least two children");
        std::vector<int> refs;
        for (std::size_t i = 0; i < children.size(); ++i)
            refs.push_back(add_csg(csg, children[i], xf, override_material, depth + 1));
        return csg.add_node(cop, std::move(refs));
    }

    if (type == "scatter") v.at("type").fail("a scatter cannot be a csg leaf (it is many objects)");
    if (type == "instance" && override_material == kNoMaterial)
        v.at("type").fail("a primitive cannot contain instances");
    Leaf leaf = parse_leaf(v, type);
    if (!leaf.solid)
        v.at("file").fail(
            "an open mesh cannot be a csg leaf: it bounds no solid (a closed mesh has every edge "
            "shared by exactly two triangles, wound the same way)");
    std::uint32_t mat;
    if (override_material) {
        mat = *override_material;
    } else if (auto m = v.find("material")) {
        mat = material(*m);
    } else {
        v.fail("missing field 'material' (needed unless an enclosing csg node sets one)");
    }
    if (override_material && v.has("material")) (void)material(v.at("material"));  // still check
    const Transform placed = xf * leaf.placement;
    require_finite_transform(placed, v);
    if (!csg.room_for(*leaf.shape))
        v.fail("a csg tree with more than " + std::to_string(kMaxCsgSurfaces) +
               " surfaces (instances of csg primitives count all of theirs)");
    return csg.add_leaf({leaf.shape, placed, mat, leaf.primitive});
}

std::shared_ptr<const TriangleMeshShape> ObjectParser::mesh(const JsonValue& object) const {
    const JsonValue file = object.at("file");
    const bool smooth = object.has("smooth") && object.at("smooth").boolean();
    const std::filesystem::path name(file.string());
    const std::string path = name.is_absolute() || file.file().empty()
                                 ? name.string()
                                 : (std::filesystem::path(file.file()).parent_path() / name).string();
    const std::string key = (smooth ? "smooth:" : "file:") + path;
    if (auto it = meshes_.find(key); it != meshes_.end()) return it->second;
    try {
        MeshData m = read_mesh_file(path);
        auto shape = std::make_shared<const TriangleMeshShape>(
            std::move(m.positions), std::move(m.triangles), std::move(m.normals), smooth);
        meshes_[key] = shape;
        return shape;
    } catch (const InputError& e) {
        file.fail(e.what());
    }
}

std::shared_ptr<const Shape> ObjectParser::parse_shape(const JsonValue& v) const {
    if (!v.is_object()) v.fail("expected an object");
    auto csg = std::make_shared<CsgShape>();
    csg->set_root(add_csg(*csg, v, Transform{}, kNoMaterial, 1));
    return csg;
}

SceneObject ObjectParser::parse(const JsonValue& v) const {
    if (!v.is_object()) v.fail("expected an object");
    const std::string type = v.at("type").string();
    SceneObject obj;
    obj.where = v.path();
    if (type == "csg") {
        // Transforms (the root's included) are folded into the leaves, so the object's is identity.
        auto csg = std::make_shared<CsgShape>();
        csg->set_root(add_csg(*csg, v, Transform{}, std::nullopt, 1));
        obj.shape = csg;
        return obj;
    }
    Transform user;
    if (auto t = v.find("transform")) user = parse_transform(*t);
    Leaf leaf = parse_leaf(v, type);
    obj.shape = leaf.shape;
    obj.xf = user * leaf.placement;
    require_finite_transform(obj.xf, v);
    obj.primitive = leaf.primitive;
    obj.material = material(v.at("material"));
    return obj;
}

}  // namespace lat
