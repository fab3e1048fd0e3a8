#pragma once
// Shared by the mesh harnesses (mesh_obj_fuzz.cpp, mesh_ply_fuzz.cpp): the input is a whole
// file's bytes, read by the format's reader; a mesh that reads is built as a shape both ways
// (flat and smooth) and traced: rays, normals, CSG spans and inside. Every input must read or
// throw InputError; anything else (a crash, a sanitizer report, another exception, a hang, a
// huge allocation) is a finding, and so is an OBJ that reads differently whole and in pieces.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_rays.h"
#include "geometry/triangle_mesh.h"
#include "io/mesh_file.h"
#include "util/error.h"

namespace lat::fuzz {

// The OBJ reader given the text in pieces of 7 bytes (lines, CR LF pairs and numbers cut
// across them), as a file is read; the message of its error, or "" and the mesh.
inline std::string parse_obj_in_pieces(std::string_view bytes, MeshData& out) {
    try {
        std::size_t at = 0;
        out = parse_obj_pieces(
            [&] {
                const std::string_view piece = bytes.substr(at, 7);
                at += piece.size();
                return piece;
            },
            "fuzz");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

inline void read_and_trace_mesh(const std::uint8_t* data, std::size_t size, MeshFormat format) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    MeshData pieces;
    const std::string pieces_error =
        format == MeshFormat::kObj ? parse_obj_in_pieces(bytes, pieces) : std::string();
    try {
        const MeshData m = parse_mesh(bytes, format, "fuzz");
        // Read whole or in pieces, the same mesh.
        if (format == MeshFormat::kObj &&
            (!pieces_error.empty() || m.positions != pieces.positions ||
             m.triangles != pieces.triangles || m.normals != pieces.normals))
            __builtin_trap();
        for (const bool smooth : {false, true}) {
            const TriangleMeshShape shape(m.positions, m.triangles, m.normals, smooth);
            trace_a_few_rays(shape, Transform{});
            SpanList spans;
            shape.spans({{0.1, -10, 0.2}, {0, 1, 0}}, spans);
            (void)shape.inside({0.1, 0.2, 0.3});
        }
    } catch (const InputError& e) {
        if (format == MeshFormat::kObj && pieces_error != e.what()) __builtin_trap();  // the same error
    }
}

}  // namespace lat::fuzz
