#include "scene/table_metadata.h"

#include <map>
#include <nlohmann/json.hpp>
#include <vector>

#include "scene/object_parser.h"
#include "scene/scene_loader.h"
#include "util/error.h"

namespace lat {

Primitive primitive_from_metadata(const TableHeader& h, const std::string& path) {
    nlohmann::json meta;
    try {
        meta = nlohmann::json::parse(h.metadata);
    } catch (const nlohmann::json::exception&) {
        throw InputError(path + ": the table's metadata is not valid JSON");
    }
    if (!meta.is_object() || !meta.contains("definition") || !meta.contains("primitive") ||
        !meta["primitive"].is_string())
        throw InputError(path + ": the table's metadata does not describe its primitive");
    const std::string where = path + " (metadata)";
    const JsonValue def(meta["definition"], "definition", where);
    const std::map<std::string, std::uint32_t> no_materials;
    const std::vector<Primitive> no_primitives;
    const ObjectParser parser(no_materials, no_primitives);
    Primitive p = parse_primitive(def, meta["primitive"].get<std::string>(), &parser);
    p.lattice = LatticeSpec{
        h.sigma, {h.cells[0] / h.sigma_inv, h.cells[1] / h.sigma_inv, h.cells[2] / h.sigma_inv}};
    // As a scene's primitive is (TablePlan): rasterizing one that sticks out (certify) would
    // start rays inside its solid.
    check_inside_box(p, where + ": ");
    return p;
}

}  // namespace lat
