#pragma once
// Triangle meshes from OBJ and PLY files, read by strict readers of our own (io/obj_reader.cpp,
// io/ply_reader.cpp) and checked so that everything after this point may trust them: finite
// vertices, indices in range, at least one triangle, sizes within the limits below. Errors
// throw InputError "<path>: [line N: ]what" (the scene reader adds the place in the scene).
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "math/vec.h"

namespace lat {

struct MeshData {
    std::vector<Vec3> positions;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    // Per vertex, the file's normal, or zero where the file gives none; empty when the file
    // gives no normal at all.
    std::vector<Vec3> normals;
};

// Far beyond the scanned models a scene uses, and small enough that the mesh and its
// hierarchy (about 100 bytes per triangle) fit in memory.
constexpr std::size_t kMaxMeshTriangles = 10'000'000;
constexpr std::size_t kMaxMeshVertices = 3 * kMaxMeshTriangles;
// Files larger than this are refused before reading. A PLY file is read whole (its binary
// body is smaller than the mesh it holds); an OBJ file a piece at a time.
constexpr std::uint64_t kMaxMeshFileBytes = std::uint64_t{1} << 30;
constexpr std::size_t kMaxObjLineBytes = std::size_t{16} << 20;

enum class MeshFormat { kObj, kPly };

// Reads the file (its format from its first bytes, "ply", or else its name's ".obj") as one
// triangle list: every object or element of faces, polygons split into triangles, points and
// lines dropped. Only the geometry is read: an OBJ's material files (mtllib) are never opened,
// since the scene gives the material.
MeshData read_mesh_file(const std::string& path);

// The same from bytes in memory; `name` stands for the file in messages.
MeshData parse_mesh(std::string_view bytes, MeshFormat format, const std::string& name);
MeshData parse_obj(std::string_view text, const std::string& name);
// OBJ text in pieces, as a file is read: next_piece() gives the next, empty at the end. Lines
// may run across pieces; only the current line is kept (at most kMaxObjLineBytes).
MeshData parse_obj_pieces(const std::function<std::string_view()>& next_piece, const std::string& name);
MeshData parse_ply(std::string_view bytes, const std::string& name);

// Checks a mesh given in memory the same way (throws InputError "<name>: what").
void check_mesh(const MeshData& m, const std::string& name);

}  // namespace lat
