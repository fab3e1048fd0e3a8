#pragma once
// The paper's Table 1 (section 2.2): for a few primitives and refinements sigma^-1, the number
// of (p_i, p_o) pairs to try, N_lp (by eq. 2 and by enumeration), the number that intersect the
// primitive, N_ix, and their ratio, beside the values the paper prints. Pairs are counted as
// the paper counts: ordered, entry and exit on different faces, a point on an edge counted on
// every face it lies on; solids are closed (a segment that touches the surface intersects it).
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/shape.h"

namespace lat {

struct Table1Cell {
    int sigma_inv = 1;
    std::array<int, 3> cells{};
    std::uint64_t n_lp_eq2 = 0, n_lp_enumerated = 0, n_ix = 0;
    double ratio = 0;
    double paper_n_lp = 0, paper_n_ix = 0, paper_ratio = 0;
    double seconds = 0;
    // Equal to the paper at its printed precision (two significant digits, ratio to 0.01).
    bool n_lp_matches = false, n_ix_matches = false, ratio_matches = false;
};

struct Table1Row {
    std::string primitive;
    std::array<double, 3> box{};
    std::vector<Table1Cell> cells;
};

// The largest box side (units) a Table 1 row may have.
inline constexpr int kMaxTable1Box = 4096;

// Empty when a cell of this box (whole units, sigma = 1) at this refinement can be counted
// here, else why not.
std::string table1_cell_error(const std::array<int, 3>& box, int sigma_inv);
// Counts one cell (table1_cell_error must be empty): N_lp both ways, N_ix and the ratio.
Table1Cell count_table1_cell(const Shape& primitive, const std::array<int, 3>& box,
                             int sigma_inv, bool progress);
// Sets the paper's printed values of a counted cell and whether ours match them.
void compare_with_paper(Table1Cell& c, double n_lp, double n_ix, double ratio);

// The paper's notation: 2.4 (3) for 2.4 x 10^3, rounded to two significant digits.
std::string paper_notation(double v);
// Whether v, to two significant digits (rounded or truncated), is the printed value p.
bool matches_printed(double v, double printed);

std::string table1_text(const std::vector<Table1Row>& rows);
nlohmann::json table1_json(const std::vector<Table1Row>& rows);

}  // namespace lat
