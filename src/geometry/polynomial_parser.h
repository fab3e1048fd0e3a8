#pragma once
// Parses a polynomial in x, y, z written as text, e.g.
//   "x^4 + y^4 + z^4 - 1"   or   "(x^2+y^2+z^2+R^2-r^2)^2 - 4*R^2*(x^2+y^2)"
// with named constants. See docs/polynomial-syntax.md for the grammar.
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>

#include "geometry/poly3.h"

namespace lat {

class PolynomialParseError : public std::runtime_error {
public:
    PolynomialParseError(std::size_t column, const std::string& what)
        : std::runtime_error(what), column_(column) {}
    // 1-based column in the text where the problem is.
    std::size_t column() const { return column_; }

private:
    std::size_t column_;
};

// Longest polynomial text accepted: a quartic written out in full is a few hundred characters;
// the limit bounds parse time and memory for hostile input.
constexpr std::size_t kMaxPolynomialLength = 10000;

// Throws PolynomialParseError on text longer than kMaxPolynomialLength, a syntax error, an unknown
// name, a division by a non-constant or by zero, a non-integer or negative exponent, or a result of
// degree over 4.
Poly3 parse_polynomial(std::string_view text, const std::map<std::string, double>& constants);

}  // namespace lat
