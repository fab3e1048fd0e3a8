#pragma once
// Sparse polynomials in x, y, z of any degree, for the polynomial parser: intermediate results
// may exceed degree 4 as long as the high terms cancel by the end.
#include <array>
#include <map>

namespace lat {

using Monomial = std::array<int, 3>;  // exponents of x, y, z

inline int total_degree(const Monomial& m) {
    return m[0] + m[1] + m[2];
}

class SparsePoly {
public:
    static SparsePoly constant(double c);
    // var 0, 1, 2 is x, y, z.
    static SparsePoly variable(int var);

    // Terms with a zero coefficient are never stored, so cancellations drop terms exactly.
    const std::map<Monomial, double>& terms() const { return terms_; }
    // -1 for the zero polynomial.
    int degree() const;
    bool is_constant() const { return degree() <= 0; }
    double constant_term() const;
    bool is_finite() const;

    void add_term(const Monomial& m, double c);

    friend SparsePoly operator+(const SparsePoly& f, const SparsePoly& g);
    friend SparsePoly operator-(const SparsePoly& f, const SparsePoly& g);
    friend SparsePoly operator-(const SparsePoly& f);
    friend SparsePoly operator*(const SparsePoly& f, const SparsePoly& g);
    // Divides each coefficient (more exact than multiplying by 1/s).
    friend SparsePoly operator/(const SparsePoly& f, double s);
    friend SparsePoly pow(const SparsePoly& f, int n);

private:
    std::map<Monomial, double> terms_;
};

}  // namespace lat
