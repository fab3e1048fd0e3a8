#pragma once
// Triangle meshes from files (OBJ, PLY, and whatever else Assimp reads), checked so that
// everything after this point may trust them: finite vertices, indices in range, at least one
// triangle. Errors throw InputError "<path>: what" (the scene reader adds the place).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "math/vec.h"

namespace lat {

struct MeshData {
    std::vector<Vec3> positions;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<Vec3> normals;  // per vertex as the file gives them; empty when it has none
};

// Far beyond the scanned models a scene uses, and small enough that the mesh and its
// hierarchy (about 100 bytes per triangle) fit in memory.
constexpr std::size_t kMaxMeshTriangles = 10'000'000;
// Files larger than this are refused before reading (Assimp reads the whole file at once).
constexpr std::uintmax_t kMaxMeshFileBytes = std::uintmax_t{1} << 30;

// Reads every mesh of the file (node transforms applied, polygons triangulated, points and
// lines ignored) as one triangle list.
MeshData read_mesh_file(const std::string& path);

// Checks a mesh given in memory the same way (throws InputError "<name>: what").
void check_mesh(const MeshData& m, const std::string& name);

}  // namespace lat
