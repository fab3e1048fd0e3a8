#include "geometry/sparse_poly.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace lat {

SparsePoly SparsePoly::constant(double c) {
    SparsePoly p;
    p.add_term({0, 0, 0}, c);
    return p;
}

SparsePoly SparsePoly::variable(int var) {
    assert(var >= 0 && var < 3);
    Monomial m{0, 0, 0};
    m[static_cast<std::size_t>(var)] = 1;
    SparsePoly p;
    p.add_term(m, 1.0);
    return p;
}

int SparsePoly::degree() const {
    int d = -1;
    for (const auto& [m, c] : terms_) d = std::max(d, total_degree(m));
    return d;
}

double SparsePoly::constant_term() const {
    const auto it = terms_.find({0, 0, 0});
    return it == terms_.end() ? 0.0 : it->second;
}

bool SparsePoly::is_finite() const {
    return std::all_of(terms_.begin(), terms_.end(),
                       [](const auto& t) { return std::isfinite(t.second); });
}

void SparsePoly::add_term(const Monomial& m, double c) {
    if (c == 0.0) return;
    const auto [it, inserted] = terms_.try_emplace(m, c);
    if (inserted) return;
    it->second += c;
    if (it->second == 0.0) terms_.erase(it);
}

SparsePoly operator+(const SparsePoly& f, const SparsePoly& g) {
    SparsePoly h = f;
    for (const auto& [m, c] : g.terms_) h.add_term(m, c);
    return h;
}

SparsePoly operator-(const SparsePoly& f, const SparsePoly& g) {
    SparsePoly h = f;
    for (const auto& [m, c] : g.terms_) h.add_term(m, -c);
    return h;
}

SparsePoly operator-(const SparsePoly& f) {
    SparsePoly h = f;
    for (auto& [m, c] : h.terms_) c = -c;
    return h;
}

SparsePoly operator*(const SparsePoly& f, const SparsePoly& g) {
    SparsePoly h;
    for (const auto& [mf, cf] : f.terms_)
        for (const auto& [mg, cg] : g.terms_)
            h.add_term({mf[0] + mg[0], mf[1] + mg[1], mf[2] + mg[2]}, cf * cg);
    return h;
}

SparsePoly operator/(const SparsePoly& f, double s) {
    SparsePoly h;
    for (const auto& [m, c] : f.terms_) h.add_term(m, c / s);
    return h;
}

SparsePoly pow(const SparsePoly& f, int n) {
    assert(n >= 0);
    // Plain repeated multiplication: the parser caps the degree, so n is small for any
    // non-constant f, and the operation order matches what a user would expand by hand.
    SparsePoly h = SparsePoly::constant(1.0);
    for (int i = 0; i < n; ++i) h = h * f;
    return h;
}

}  // namespace lat
