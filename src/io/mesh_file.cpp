#include "io/mesh_file.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "util/error.h"

namespace lat {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
    throw InputError(located_message(path, "", what));
}

bool has_extension(const std::string& path, const char* ext) {
    std::string e = std::filesystem::path(path).extension().string();
    for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return e == ext;
}

// Assimp reads "nan" or "1e999" in an OBJ without complaint (as some finite number), so the
// vertex lines are checked here first: every number finite and fully read.
void check_obj_numbers(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    for (long n = 1; std::getline(in, line); ++n) {
        if (line.size() < 2 || line[0] != 'v' || (line[1] != ' ' && line[1] != '\t' && line[1] != 'n'))
            continue;
        std::istringstream tokens(line.substr(line[1] == 'n' ? 2 : 1));
        std::string tok;
        while (tokens >> tok) {
            char* end = nullptr;
            const double x = std::strtod(tok.c_str(), &end);
            if (*end != '\0' || !std::isfinite(x))
                fail(path, "line " + std::to_string(n) + ": '" + tok.substr(0, 40) +
                               "' is not a finite number");
        }
    }
}

// A PLY header may claim any number of elements, and Assimp allocates for the claim before
// reading: a few bytes can ask for gigabytes. Each element takes at least one byte of the file,
// so a claim beyond the file's size is refused up front. ASCII bodies are checked as OBJ ones
// are (Assimp reads "nan" there as some finite number too).
void check_ply(const std::string& path, std::uintmax_t size) {
    std::ifstream in(path, std::ios::binary);
    std::string line;
    bool ascii = false;
    long n = 0;
    while (std::getline(in, line) && ++n < 1000) {
        if (line.rfind("end_header", 0) == 0) break;
        std::istringstream words(line);
        std::string kw, name;
        double count = 0;
        if (line.rfind("format ascii", 0) == 0) ascii = true;
        if (words >> kw >> name >> count && kw == "element" && count > static_cast<double>(size))
            fail(path, "the PLY header claims " + std::to_string(static_cast<long long>(std::min(count, 1e18))) +
                           " " + name + " elements, more than the file's " + std::to_string(size) +
                           " bytes can hold");
    }
    while (ascii && std::getline(in, line)) {
        ++n;
        std::istringstream tokens(line);
        std::string tok;
        while (tokens >> tok) {
            char* end = nullptr;
            const double x = std::strtod(tok.c_str(), &end);
            if (*end != '\0' || !std::isfinite(x))
                fail(path, "line " + std::to_string(n) + ": '" + tok.substr(0, 40) + "' is not a finite number");
        }
    }
}

// Assimp's own message for a file it cannot open is vague ("Unable to open file"), so the
// usual failures are told apart first.
void check_readable(const std::string& path) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(status)) fail(path, "cannot open mesh file: No such file or directory");
    if (std::filesystem::is_directory(status)) fail(path, "cannot open mesh file: it is a directory");
    if (!std::ifstream(path, std::ios::binary)) fail(path, "cannot open mesh file: permission denied");
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) fail(path, "cannot open mesh file: " + ec.message());
    if (size > kMaxMeshFileBytes)
        fail(path, "mesh file of " + std::to_string(size) + " bytes is over the limit of " +
                       std::to_string(kMaxMeshFileBytes) + " bytes");
    if (has_extension(path, ".obj")) check_obj_numbers(path);
    if (has_extension(path, ".ply")) check_ply(path, size);
}

Vec3 to_vec(const aiVector3D& v) {
    return {static_cast<double>(v.x), static_cast<double>(v.y), static_cast<double>(v.z)};
}

}  // namespace

void check_mesh(const MeshData& m, const std::string& name) {
    if (m.triangles.empty()) fail(name, "the mesh has no triangles");
    if (m.triangles.size() > kMaxMeshTriangles)
        fail(name, std::to_string(m.triangles.size()) + " triangles is over the limit of " +
                       std::to_string(kMaxMeshTriangles));
    for (std::size_t i = 0; i < m.positions.size(); ++i)
        if (!is_finite(m.positions[i]))
            fail(name, "vertex " + std::to_string(i) + " is not finite (NaN or infinite)");
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
        for (const std::uint32_t k : m.triangles[t])
            if (k >= m.positions.size())
                fail(name, "triangle " + std::to_string(t) + " refers to vertex " +
                               std::to_string(k) + ", but the mesh has " +
                               std::to_string(m.positions.size()) + " vertices");
    if (!m.normals.empty() && m.normals.size() != m.positions.size())
        fail(name, "the mesh has " + std::to_string(m.normals.size()) + " normals for " +
                       std::to_string(m.positions.size()) + " vertices");
}

MeshData read_mesh_file(const std::string& path) {
    check_readable(path);
    Assimp::Importer importer;
    // Points and lines are of no use to a ray tracer of surfaces: drop them on import.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                           aiProcess_PreTransformVertices | aiProcess_SortByPType |
                           aiProcess_ValidateDataStructure;
    const aiScene* scene = importer.ReadFile(path, flags);
    if (!scene) {
        const std::string why = importer.GetErrorString();
        if (why.find("contains no faces") != std::string::npos) fail(path, "the mesh has no triangles");
        fail(path, "cannot read mesh: " + why);
    }

    MeshData out;
    bool all_normals = true;
    for (unsigned k = 0; k < scene->mNumMeshes; ++k)
        all_normals = all_normals && scene->mMeshes[k]->HasNormals();
    for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
        const aiMesh& mesh = *scene->mMeshes[k];
        if (!(mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        const auto base = static_cast<std::uint32_t>(out.positions.size());
        for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
            out.positions.push_back(to_vec(mesh.mVertices[v]));
            if (all_normals) out.normals.push_back(to_vec(mesh.mNormals[v]));
        }
        for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
            const aiFace& face = mesh.mFaces[f];
            if (face.mNumIndices != 3) continue;
            for (int i = 0; i < 3; ++i)
                if (face.mIndices[i] >= mesh.mNumVertices)
                    fail(path, "a face refers to vertex " + std::to_string(face.mIndices[i]) +
                                   ", but its mesh has " + std::to_string(mesh.mNumVertices) +
                                   " vertices");
            out.triangles.push_back({base + face.mIndices[0], base + face.mIndices[1],
                                     base + face.mIndices[2]});
            if (out.triangles.size() > kMaxMeshTriangles) break;
        }
    }
    check_mesh(out, path);
    return out;
}

}  // namespace lat
