#include "scene/table1_file.h"

#include <cmath>

#include "scene/json_reader.h"
#include "scene/scene_loader.h"

namespace lat {

std::vector<Table1Row> compute_table1(const std::string& path, bool progress) {
    const nlohmann::json doc = parse_json_file(path);
    const JsonValue root(doc, "", path);
    if (!root.is_object()) root.fail("a Table 1 file must hold a JSON object");
    root.allow_keys({"format", "rows"});
    const JsonValue rows = root.at("rows");
    std::vector<Table1Row> out;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const JsonValue r = rows[i];
        r.allow_keys({"primitive", "shape", "box_world", "paper"});
        Table1Row row;
        row.primitive = r.at("primitive").string();
        const Primitive prim = parse_primitive(r.at("shape"), row.primitive);
        const JsonValue box_value = r.at("box_world");
        const Vec3 b = box_value.vec3();
        std::array<int, 3> box{};
        for (std::size_t a = 0; a < 3; ++a) {
            if (!(b[a] >= 1 && b[a] <= kMaxTable1Box && b[a] == std::floor(b[a])))
                box_value[a].fail("the box must be a whole number of units (sigma = 1) along each "
                                  "axis, at most " + std::to_string(kMaxTable1Box));
            row.box[a] = b[a];
            box[a] = static_cast<int>(b[a]);
        }
        const JsonValue paper = r.at("paper");
        for (std::size_t k = 0; k < paper.size(); ++k) {
            const JsonValue p = paper[k];
            p.allow_keys({"sigma_inv", "N_lp", "N_ix", "ratio"});
            const int sigma_inv = p.at("sigma_inv").integer();
            if (const std::string e = table1_cell_error(box, sigma_inv); !e.empty())
                p.at("sigma_inv").fail(e);
            Table1Cell c = count_table1_cell(*prim.shape, box, sigma_inv, progress);
            compare_with_paper(c, p.at("N_lp").number(), p.at("N_ix").number(),
                               p.at("ratio").number());
            row.cells.push_back(c);
        }
        out.push_back(std::move(row));
    }
    return out;
}

}  // namespace lat
