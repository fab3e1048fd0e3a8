#pragma once
// Reading the "objects" list: quartics by name, by coefficients or as text, instances of
// primitives, and CSG trees over any of them.
#include <map>
#include <optional>
#include <string>

#include "csg/csg_shape.h"
#include "geometry/triangle_mesh.h"
#include "scene/json_reader.h"
#include "scene/scene.h"

namespace lat {

// Deepest CSG tree a scene may hold: far beyond real scenes; parsing and tracing recurse per
// level, so the limit keeps the stack bounded.
constexpr int kMaxCsgDepth = 256;

class ObjectParser {
public:
    ObjectParser(const std::map<std::string, std::uint32_t>& materials,
                 const std::vector<Primitive>& primitives);

    SceneObject parse(const JsonValue& v) const;
    // The solid alone, materials ignored (for primitives given as an object; instances of
    // them take the instance's material).
    std::shared_ptr<const Shape> parse_shape(const JsonValue& v) const;
    // The index of the material named by v.
    std::uint32_t material_index(const JsonValue& v) const { return material(v); }
    // The mesh of a mesh object: its "file" (relative to the scene file's directory), shaded as
    // its "smooth" says.
    std::shared_ptr<const TriangleMeshShape> mesh(const JsonValue& object) const;

private:
    const std::map<std::string, std::uint32_t>& materials_;
    const std::vector<Primitive>& primitives_;

    // Meshes by resolved path (and smoothing), read once per scene however often they are used.
    mutable std::map<std::string, std::shared_ptr<const TriangleMeshShape>> meshes_;

    std::uint32_t material(const JsonValue& v) const;
    // A leaf's geometry in its own frame, with the placement that its parameters imply.
    struct Leaf {
        std::shared_ptr<const Shape> shape;
        Transform placement;
        int primitive = -1;
        bool solid = true;  // false: an open mesh, which bounds no solid (no CSG leaf)
    };
    Leaf parse_leaf(const JsonValue& v, const std::string& type) const;
    // Adds v's subtree to csg; `to_root` maps v's parent frame to the CSG root frame; `depth`
    // is v's depth in the tree (the root is 1), limited to kMaxCsgDepth.
    int add_csg(CsgShape& csg, const JsonValue& v, const Transform& to_root,
                std::optional<std::uint32_t> override_material, int depth) const;
};

}  // namespace lat
