// OBJ files -> MeshData (parse_obj) -> TriangleMeshShape, traced (see mesh_fuzz.h).
#include "mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    lat::fuzz::read_and_trace_mesh(data, size, lat::MeshFormat::kObj);
    return 0;
}
