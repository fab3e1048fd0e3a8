// Why readers of our own rather than Assimp: fuzzing found Assimp 5.2.5 (Debian's) crashing,
// hanging and allocating gigabytes on small PLY files (a NUL in the header, a face of 0
// indices, a second vertex element, a header without end_header, a face list claiming 1.34e9
// indices), reading an OBJ's material files whole and unchecked (any size, FIFOs), costing time
// quadratic in the number of materials, and leaking on bad indices. Each fix inside or before
// it would cover one instance of a class; a checked pre-parse would have to understand the
// whole format anyway. OBJ and PLY are small formats, and a reader that allocates only for what
// it has read, checks every count against the bytes that remain and never opens another file
// holds for the whole class. It is fuzzed (fuzz/mesh_obj_fuzz.cpp, fuzz/mesh_ply_fuzz.cpp).
#include "io/mesh_file.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string_view>
#include <vector>

#include "io/mesh_builder.h"
#include "util/error.h"
#include "util/file.h"

namespace lat {
namespace mesh_io {

void fail(const std::string& name, const std::string& where, const std::string& what) {
    throw InputError(located_message(name, where, what));
}

std::string not_a_number(std::string_view token) {
    return quoted(token) + " is not a finite number";
}

namespace {

template <class T>
bool parse_real(std::string_view token, T& out) {
    if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
    const char* end = token.data() + token.size();
    const auto [ptr, ec] = std::from_chars(token.data(), end, out);
    if (ptr != end || token.empty()) return false;
    if (ec == std::errc::result_out_of_range) {
        // from_chars says so on underflow too: then the value rounds to 0 or a denormal.
        if (token.size() > 64) return false;
        const std::string copy(token);
        const long double x = std::strtold(copy.c_str(), nullptr);
        if (!(std::fabs(x) <= static_cast<long double>(std::numeric_limits<T>::max()))) return false;  // overflow
        out = static_cast<T>(x);
    } else if (ec != std::errc()) {
        return false;
    }
    return std::isfinite(out);
}

}  // namespace

bool parse_float(std::string_view token, float& out) { return parse_real(token, out); }
bool parse_double(std::string_view token, double& out) { return parse_real(token, out); }

bool parse_int(std::string_view token, std::int64_t& out) {
    if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
    const char* end = token.data() + token.size();
    const auto [ptr, ec] = std::from_chars(token.data(), end, out);
    return ec == std::errc() && ptr == end && !token.empty();
}

std::uint32_t MeshBuilder::add_vertex(Vec3 p, Vec3 n) {
    if (out_.positions.size() >= kMaxMeshVertices)
        fail(name_, place_(), "more than " + std::to_string(kMaxMeshVertices) + " vertices, the limit");
    out_.positions.push_back(p);
    out_.normals.push_back(n);
    any_normal_ = any_normal_ || n != Vec3{};
    return static_cast<std::uint32_t>(out_.positions.size() - 1);
}

void MeshBuilder::add_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (out_.triangles.size() >= kMaxMeshTriangles)
        fail(name_, place_(), "more than " + std::to_string(kMaxMeshTriangles) + " triangles, the limit");
    out_.triangles.push_back({a, b, c});
}

// A fan from the first corner, which is right for convex polygons; a quad is split along the
// diagonal that stays inside it (the one through its reflex corner, if it has one).
void MeshBuilder::add_face(std::span<const std::uint32_t> v, std::size_t face) {
    if (v.size() < 3) {
        if (first_dropped_.empty())
            first_dropped_ = located_message("", place_(), "face " + std::to_string(face)) + " has " + std::to_string(v.size()) +
                             (v.size() == 1 ? " vertex" : " vertices");
        return;
    }
    if (v.size() == 4) {
        const auto& p = out_.positions;
        const Vec3 a = p[v[0]], b = p[v[1]], c = p[v[2]], d = p[v[3]];
        const Vec3 n = cross(c - a, d - b);
        const bool reflex_b = dot(cross(b - a, c - b), n) < 0;
        const bool reflex_d = dot(cross(d - c, a - d), n) < 0;
        if (reflex_b || reflex_d) {
            add_triangle(v[0], v[1], v[3]);
            add_triangle(v[1], v[2], v[3]);
            return;
        }
    }
    for (std::size_t k = 1; k + 1 < v.size(); ++k) add_triangle(v[0], v[k], v[k + 1]);
}

MeshData MeshBuilder::finish() {
    if (out_.triangles.empty())
        fail(name_, "", first_dropped_.empty()
                            ? "the mesh has no triangles"
                            : "the mesh has no triangles: " + first_dropped_ +
                                  ", and points and lines are dropped");
    if (!any_normal_) out_.normals.clear();
    check_mesh(out_, name_);
    return std::move(out_);
}

}  // namespace mesh_io

void check_mesh(const MeshData& m, const std::string& name) {
    using mesh_io::fail;
    if (m.triangles.empty()) fail(name, "", "the mesh has no triangles");
    if (m.triangles.size() > kMaxMeshTriangles)
        fail(name, "", std::to_string(m.triangles.size()) + " triangles is over the limit of " +
                           std::to_string(kMaxMeshTriangles));
    for (std::size_t i = 0; i < m.positions.size(); ++i)
        if (!is_finite(m.positions[i]))
            fail(name, "", "vertex " + std::to_string(i) + " is not finite (NaN or infinite)");
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
        for (const std::uint32_t k : m.triangles[t])
            if (k >= m.positions.size())
                fail(name, "", "triangle " + std::to_string(t) + " refers to vertex " +
                                   std::to_string(k) + ", but the mesh has " +
                                   std::to_string(m.positions.size()) + " vertices");
    if (!m.normals.empty() && m.normals.size() != m.positions.size())
        fail(name, "", "the mesh has " + std::to_string(m.normals.size()) + " normals for " +
                           std::to_string(m.positions.size()) + " vertices");
    for (std::size_t i = 0; i < m.normals.size(); ++i)
        if (!is_finite(m.normals[i]))
            fail(name, "", "the normal of vertex " + std::to_string(i) + " is not finite");
}

MeshData parse_mesh(std::string_view bytes, MeshFormat format, const std::string& name) {
    return format == MeshFormat::kPly ? parse_ply(bytes, name) : parse_obj(bytes, name);
}

MeshData read_mesh_file(const std::string& path) {
    InputFile file(path, "mesh file", kMaxMeshFileBytes);
    std::vector<char> buf(std::size_t{1} << 20);
    std::size_t head = 0;  // the first bytes, enough to tell a PLY file
    while (head < 4) {
        const std::size_t n = file.read_some(buf.data() + head, buf.size() - head);
        if (n == 0) break;
        head += n;
    }
    const std::string_view first(buf.data(), head);
    std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const bool ply = first.starts_with("ply") && (head == 3 || first[3] == '\n' || first[3] == '\r');
    if (ply || ext == ".ply") {  // a .ply that does not start so is told what is wrong with it
        std::string bytes;  // read whole, once: no second copy of a large file
        bytes.reserve(static_cast<std::size_t>(file.size()));
        bytes.append(first);
        while (const std::size_t n = file.read_some(buf.data(), buf.size())) bytes.append(buf.data(), n);
        return parse_ply(bytes, path);
    }
    if (ext != ".obj")
        mesh_io::fail(path, "", "not a mesh file this program reads: OBJ (.obj) or PLY (a file "
                                "that starts with 'ply')");
    bool first_piece = true;
    return parse_obj_pieces(
        [&]() -> std::string_view {
            if (first_piece) {
                first_piece = false;
                if (head > 0) return first;
            }
            return {buf.data(), file.read_some(buf.data(), buf.size())};
        },
        path);
}

}  // namespace lat
