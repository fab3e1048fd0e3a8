#pragma once
// Shared by the mesh harnesses (mesh_obj_fuzz.cpp, mesh_ply_fuzz.cpp): the input is a whole
// file's bytes, read by the format's reader; a mesh that reads is built as a shape both ways
// (flat and smooth) and traced: rays, normals, CSG spans and inside. Every input must read or
// throw InputError; anything else (a crash, a sanitizer report, another exception, a hang, a
// huge allocation) is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_rays.h"
#include "geometry/triangle_mesh.h"
#include "io/mesh_file.h"
#include "util/error.h"

namespace lat::fuzz {

inline void read_and_trace_mesh(const std::uint8_t* data, std::size_t size, MeshFormat format) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    try {
        const MeshData m = parse_mesh(bytes, format, "fuzz");
        for (const bool smooth : {false, true}) {
            const TriangleMeshShape shape(m.positions, m.triangles, m.normals, smooth);
            trace_a_few_rays(shape, Transform{});
            SpanList spans;
            shape.spans({{0.1, -10, 0.2}, {0, 1, 0}}, spans);
            (void)shape.inside({0.1, 0.2, 0.3});
        }
    } catch (const InputError&) {
    }
}

}  // namespace lat::fuzz
