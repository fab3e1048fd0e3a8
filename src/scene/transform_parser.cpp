// "transform": a 3 x 4 (or 4 x 4 affine) row-major matrix, or a list of operations applied to
// the object in the order written: {"translate": [x,y,z]}, {"scale": s | [sx,sy,sz]},
// {"rotate": {"axis": [x,y,z], "angle_deg": a}}, {"matrix": [[...], [...], [...]]}.
#include <cmath>

#include "scene/scene_loader.h"

namespace lat {
namespace {

Affine parse_matrix(const JsonValue& v) {
    const std::size_t rows = v.size();
    if (rows != 3 && rows != 4) v.fail("expected a 3 x 4 matrix (3 rows of 4 numbers)");
    Affine a;
    for (std::size_t i = 0; i < rows; ++i) {
        const JsonValue row = v[i];
        if (!row.is_array() || row.size() != 4) row.fail("expected a row of 4 numbers");
        if (i == 3) {
            if (row[0].number() != 0 || row[1].number() != 0 || row[2].number() != 0 ||
                row[3].number() != 1)
                row.fail("the last row of a 4 x 4 matrix must be [0, 0, 0, 1]");
            continue;
        }
        a.m.r[i] = {row[0].number(), row[1].number(), row[2].number()};
        a.t[i] = row[3].number();
    }
    return a;
}

Transform checked(const Affine& a, const JsonValue& where) {
    auto t = Transform::from_affine(a);
    if (!t) where.fail("matrix is singular (it flattens space, so it cannot be inverted)");
    return *t;
}

Transform parse_op(const JsonValue& op) {
    if (!op.is_object() || op.keys().size() != 1)
        op.fail("expected one operation: {\"translate\": ...}, {\"rotate\": ...}, "
                "{\"scale\": ...} or {\"matrix\": ...}");
    const std::string kind = op.keys()[0];
    const JsonValue arg = op.at(kind);
    if (kind == "translate") return Transform::translate(arg.vec3());
    if (kind == "scale") {
        Vec3 s;
        if (arg.is_number()) {
            const double k = arg.number();
            s = {k, k, k};
        } else {
            s = arg.vec3();
        }
        if (s.x == 0 || s.y == 0 || s.z == 0) arg.fail("scale factors must be non-zero");
        return Transform::scale(s);
    }
    if (kind == "rotate") {
        arg.allow_keys({"axis", "angle_deg"});
        const Vec3 axis = arg.at("axis").direction();
        const double deg = arg.at("angle_deg").number();
        return Transform::rotate(axis, deg * M_PI / 180.0);
    }
    if (kind == "matrix") return checked(parse_matrix(arg), arg);
    op.fail("unknown transform operation '" + kind +
            "' (expected translate, rotate, scale or matrix)");
}

}  // namespace

void require_finite_transform(const Transform& t, const JsonValue& v) {
    const Affine& f = t.forward();
    const Affine& i = t.inverse_map();
    bool ok = is_finite(f.t) && is_finite(i.t);
    for (std::size_t r = 0; r < 3; ++r) ok = ok && is_finite(f.m.r[r]) && is_finite(i.m.r[r]);
    if (!ok) v.fail("the transform overflows the range of a double (or its inverse does)");
}

Transform parse_transform(const JsonValue& v) {
    if (!v.is_array() || v.size() == 0)
        v.fail("expected a 3 x 4 matrix or a list of operations");
    if (v[0].is_array()) return checked(parse_matrix(v), v);
    Transform t;
    for (std::size_t i = 0; i < v.size(); ++i) t = parse_op(v[i]) * t;  // later ops apply last
    require_finite_transform(t, v);
    return t;
}

}  // namespace lat
