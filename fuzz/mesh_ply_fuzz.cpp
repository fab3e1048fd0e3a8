// PLY files -> MeshData (parse_ply) -> TriangleMeshShape, traced (see mesh_fuzz.h).
#include "mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    lat::fuzz::read_and_trace_mesh(data, size, lat::MeshFormat::kPly);
    return 0;
}
