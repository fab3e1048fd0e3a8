#include "lattice/table1.h"

#include <cassert>
#include <cmath>
#include <cstdio>

#include "lattice/boundary_grid.h"
#include "lattice/rasterizer.h"

namespace lat {
namespace {

// Counting is exhaustive: beyond this many pairs (minutes of work) a cell is refused.
constexpr double kMaxTable1Pairs = 1e11;

// Two significant digits, as the paper prints them.
double round2(double v) {
    if (v == 0) return 0;
    const double e = std::floor(std::log10(std::abs(v)));
    const double scale = std::pow(10.0, e - 1);
    return std::round(v / scale) * scale;
}

}  // namespace

std::string paper_notation(double v) {
    if (v <= 0) return "0";
    const double r = round2(v);
    const int e = static_cast<int>(std::floor(std::log10(r) + 1e-12));
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f (%d)", r / std::pow(10.0, e), e);
    return buf;
}

// The paper rounds most values but truncates some (its text gives N_lp = 9,950 for the hook,
// printed 9.9 (3)): either reading of the printed digits counts as a match.
bool matches_printed(double v, double printed) {
    if (v <= 0 || printed <= 0) return v == printed;
    const double e = std::floor(std::log10(v));
    const double scale = std::pow(10.0, e - 1);
    const double rounded = std::round(v / scale) * scale, truncated = std::floor(v / scale) * scale;
    const double tol = 1e-9 * printed;
    return std::abs(rounded - printed) <= tol || std::abs(truncated - printed) <= tol;
}

Table1Cell count_table1_cell(const Shape& primitive, const std::array<int, 3>& box,
                             int sigma_inv, bool progress) {
    assert(table1_cell_error(box, sigma_inv).empty());
    Table1Cell c;
    c.sigma_inv = sigma_inv;
    TableContext g{{}, 1.0 / sigma_inv, 1.0, &primitive};
    for (std::size_t a = 0; a < 3; ++a) g.cells[a] = box[a] * sigma_inv;
    c.cells = g.cells;
    RasterizeOptions opt;
    opt.keep_hits = false;
    opt.progress = progress;
    const RasterizeResult res = rasterize(g, opt);
    c.n_lp_eq2 = res.pairs_eq2;
    c.n_lp_enumerated = res.pairs_enumerated;
    c.n_ix = res.hits_counted;
    c.ratio = double(c.n_ix) / double(c.n_lp_eq2);
    c.seconds = res.seconds;
    return c;
}

void compare_with_paper(Table1Cell& c, double n_lp, double n_ix, double ratio) {
    c.paper_n_lp = n_lp;
    c.paper_n_ix = n_ix;
    c.paper_ratio = ratio;
    c.n_lp_matches = matches_printed(double(c.n_lp_eq2), n_lp);
    c.n_ix_matches = matches_printed(double(c.n_ix), n_ix);
    c.ratio_matches = std::abs(std::round(c.ratio * 100) / 100 - ratio) < 1e-9;
}

std::string table1_cell_error(const std::array<int, 3>& box, int sigma_inv) {
    for (const int b : box)
        if (b < 1 || b > kMaxTable1Box) return "the box must be 1 to 4096 units along each axis";
    if (std::string e = sigma_inv_error(sigma_inv); !e.empty()) return e;
    const std::array<int, 3> cells{box[0] * sigma_inv, box[1] * sigma_inv, box[2] * sigma_inv};
    if (BoundaryGrid::pair_count(cells) > static_cast<long double>(kMaxTable1Pairs))
        return "the lattice has too many point pairs to count here (more than " +
               paper_notation(kMaxTable1Pairs) + ")";
    return {};
}

std::string table1_text(const std::vector<Table1Row>& rows) {
    std::string s;
    char buf[512];
    std::snprintf(buf, sizeof buf, "%-40s %4s %-11s  %-9s %10s %10s   %-9s %9s %9s   %-5s %5s\n",
                  "primitive", "s^-1", "cells", "N_lp", "eq. (2)", "enumerated", "N_ix", "",
                  "counted", "ratio", "");
    s += buf;
    std::snprintf(buf, sizeof buf, "%-40s %4s %-11s  %-9s %10s %10s   %-9s %9s %9s   %-5s %5s\n", "",
                  "", "", "paper", "", "", "paper", "ours", "", "paper", "ours");
    s += buf;
    for (const Table1Row& r : rows) {
        const char* name = r.primitive.c_str();
        bool first = true;
        for (const Table1Cell& c : r.cells) {
            char cells[32];
            std::snprintf(cells, sizeof cells, "%dx%dx%d", c.cells[0], c.cells[1], c.cells[2]);
            std::snprintf(buf, sizeof buf,
                          "%-40.40s %4d %-11s  %-9s %10llu %10llu%s  %-9s %9s %9llu%s  %-5.2f %5.3f%s\n",
                          first ? name : "", c.sigma_inv, cells, paper_notation(c.paper_n_lp).c_str(),
                          static_cast<unsigned long long>(c.n_lp_eq2),
                          static_cast<unsigned long long>(c.n_lp_enumerated), c.n_lp_matches ? " " : "*",
                          paper_notation(c.paper_n_ix).c_str(), paper_notation(double(c.n_ix)).c_str(),
                          static_cast<unsigned long long>(c.n_ix), c.n_ix_matches ? " " : "*",
                          c.paper_ratio, c.ratio, c.ratio_matches ? "" : " *");
            s += buf;
            first = false;
        }
    }
    s += "* differs from the paper at its printed precision (two significant digits, rounded or\n"
         "  truncated as the paper does; the ratio to 0.01)\n";
    return s;
}

nlohmann::json table1_json(const std::vector<Table1Row>& rows) {
    nlohmann::json out = nlohmann::json::array();
    for (const Table1Row& r : rows) {
        nlohmann::json jr;
        jr["primitive"] = r.primitive;
        jr["box"] = r.box;
        for (const Table1Cell& c : r.cells) {
            jr["cells"].push_back({{"sigma_inv", c.sigma_inv},
                                   {"lattice_cells", c.cells},
                                   {"N_lp_eq2", c.n_lp_eq2},
                                   {"N_lp_enumerated", c.n_lp_enumerated},
                                   {"N_ix", c.n_ix},
                                   {"ratio", c.ratio},
                                   {"paper", {{"N_lp", c.paper_n_lp}, {"N_ix", c.paper_n_ix}, {"ratio", c.paper_ratio}}},
                                   {"matches_paper", {{"N_lp", c.n_lp_matches}, {"N_ix", c.n_ix_matches}, {"ratio", c.ratio_matches}}},
                                   {"seconds", c.seconds}});
        }
        out.push_back(jr);
    }
    return out;
}

}  // namespace lat
