#pragma once
// What the OBJ and PLY readers share: numbers read strictly from text, and the mesh they build
// (vertices, polygons split into triangles, the limits). Internal to io/.
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>

#include "io/mesh_file.h"

namespace lat::mesh_io {

// The whole token as a number, or false: no sign but '-' and '+', no trailing bytes; a float
// must be finite once rounded to float (values too small for a float round to 0 or a denormal).
bool parse_float(std::string_view token, float& out);
bool parse_double(std::string_view token, double& out);
bool parse_int(std::string_view token, std::int64_t& out);

// "'<token>' is not a finite number", the token escaped and capped.
std::string not_a_number(std::string_view token);

// Throws InputError "name: where: what" (where may be empty).
[[noreturn]] void fail(const std::string& name, const std::string& where, const std::string& what);

class MeshBuilder {
public:
    // `place` says where the reader is ("line 12", or "" where lines mean nothing), for messages.
    MeshBuilder(std::string name, std::function<std::string()> place)
        : name_(std::move(name)), place_(std::move(place)) {}

    std::size_t vertex_count() const { return out_.positions.size(); }
    // A vertex at p with the file's normal n, or none when n is zero. Returns its index.
    std::uint32_t add_vertex(Vec3 p, Vec3 n);
    // Face number `face` (from 1) of the file, as indices from add_vertex: split into
    // triangles, or dropped (noted for the message should the mesh end up empty) when it has
    // fewer than 3 corners.
    void add_face(std::span<const std::uint32_t> corners, std::size_t face);
    // The mesh, checked (throws "the mesh has no triangles", with the first dropped face named).
    MeshData finish();

private:
    std::string name_;
    std::function<std::string()> place_;
    MeshData out_;
    bool any_normal_ = false;
    std::string first_dropped_;  // "face 3 has 2 vertices" of the first face dropped

    void add_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c);
};

}  // namespace lat::mesh_io
