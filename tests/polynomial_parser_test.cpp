// The polynomial grammar feature by feature (docs/polynomial-syntax.md).
#include "geometry/polynomial_parser.h"

#include <gtest/gtest.h>

#include <array>
#include <map>
#include <numbers>

namespace lat {
namespace {

using Terms = std::map<std::array<int, 3>, double>;

const std::map<std::string, double> kConstants = {{"R", 2.0},    {"r", 0.5},      {"n", 2.0},
                                                  {"half", 0.5}, {"radius", 1.5}, {"r_2", 4.0}};

Poly3 parse(std::string_view text) {
    return parse_polynomial(text, kConstants);
}

// The non-zero coefficients, keyed by exponents (i, j, k) of x^i y^j z^k.
Terms terms(const Poly3& p) {
    Terms out;
    for (int n = 0; n < Poly3::kTerms; ++n)
        if (p.a[static_cast<std::size_t>(n)] != 0.0)
            out[Poly3::exponents(n)] = p.a[static_cast<std::size_t>(n)];
    return out;
}

Terms terms(std::string_view text) {
    return terms(parse(text));
}

constexpr std::array<int, 3> k1{0, 0, 0}, kX{1, 0, 0}, kY{0, 1, 0}, kZ{0, 0, 1};

TEST(PolynomialParser, Numbers) {
    EXPECT_EQ(terms("2"), (Terms{{k1, 2.0}}));
    EXPECT_EQ(terms("0.5"), (Terms{{k1, 0.5}}));
    EXPECT_EQ(terms(".5"), (Terms{{k1, 0.5}}));
    EXPECT_EQ(terms("2."), (Terms{{k1, 2.0}}));
    EXPECT_EQ(terms("1e-3"), (Terms{{k1, 1e-3}}));
    EXPECT_EQ(terms("2.5E+2"), (Terms{{k1, 250.0}}));
    EXPECT_EQ(terms("1E3"), (Terms{{k1, 1000.0}}));
    EXPECT_EQ(terms("007"), (Terms{{k1, 7.0}}));
    EXPECT_EQ(terms("0"), Terms{});
    EXPECT_EQ(parse("0").degree(), -1);
}

TEST(PolynomialParser, VariablesAndConstants) {
    EXPECT_EQ(terms("x"), (Terms{{kX, 1.0}}));
    EXPECT_EQ(terms("y"), (Terms{{kY, 1.0}}));
    EXPECT_EQ(terms("z"), (Terms{{kZ, 1.0}}));
    EXPECT_EQ(terms("R"), (Terms{{k1, 2.0}}));
    EXPECT_EQ(terms("r"), (Terms{{k1, 0.5}}));  // names are case sensitive
    EXPECT_EQ(terms("r_2"), (Terms{{k1, 4.0}}));
    EXPECT_EQ(terms("pi"), (Terms{{k1, std::numbers::pi}}));
    // The map overrides the built-in pi.
    EXPECT_EQ(terms(parse_polynomial("pi", {{"pi", 3.0}})), (Terms{{k1, 3.0}}));
}

TEST(PolynomialParser, BinaryOperators) {
    EXPECT_EQ(terms("x + y"), (Terms{{kX, 1.0}, {kY, 1.0}}));
    EXPECT_EQ(terms("x - y"), (Terms{{kX, 1.0}, {kY, -1.0}}));
    EXPECT_EQ(terms("x * y"), (Terms{{{1, 1, 0}, 1.0}}));
    EXPECT_EQ(terms("x / 4"), (Terms{{kX, 0.25}}));
    EXPECT_EQ(terms("x / R"), (Terms{{kX, 0.5}}));
    EXPECT_EQ(terms("x / (1 + 1)"), (Terms{{kX, 0.5}}));
    // The divisor is checked after simplification: y - y + 2 is the constant 2.
    EXPECT_EQ(terms("x / (y - y + 2)"), (Terms{{kX, 0.5}}));
}

TEST(PolynomialParser, LeftAssociativeSumsAndProducts) {
    EXPECT_EQ(terms("x - y - z"), (Terms{{kX, 1.0}, {kY, -1.0}, {kZ, -1.0}}));
    EXPECT_EQ(terms("8 / 4 / 2"), (Terms{{k1, 1.0}}));
    EXPECT_EQ(terms("x / 4 / 2"), (Terms{{kX, 0.125}}));
    EXPECT_EQ(terms("8 / 4 * 2"), (Terms{{k1, 4.0}}));
    EXPECT_EQ(terms("1 - 2 + 3"), (Terms{{k1, 2.0}}));
}

TEST(PolynomialParser, Precedence) {
    EXPECT_EQ(terms("1 + 2 * 3"), (Terms{{k1, 7.0}}));
    EXPECT_EQ(terms("2 * 3 + 1"), (Terms{{k1, 7.0}}));
    EXPECT_EQ(terms("(1 + 2) * 3"), (Terms{{k1, 9.0}}));
    EXPECT_EQ(terms("2 * 3^2"), (Terms{{k1, 18.0}}));
    EXPECT_EQ(terms("1 + 2^2 * 3"), (Terms{{k1, 13.0}}));
    EXPECT_EQ(terms("x + y * z"), (Terms{{kX, 1.0}, {{0, 1, 1}, 1.0}}));
}

TEST(PolynomialParser, UnaryOperators) {
    EXPECT_EQ(terms("-x"), (Terms{{kX, -1.0}}));
    EXPECT_EQ(terms("+x"), (Terms{{kX, 1.0}}));
    EXPECT_EQ(terms("--x"), (Terms{{kX, 1.0}}));
    EXPECT_EQ(terms("-+-x"), (Terms{{kX, 1.0}}));
    EXPECT_EQ(terms("x - -y"), (Terms{{kX, 1.0}, {kY, 1.0}}));
    EXPECT_EQ(terms("x * -y"), (Terms{{{1, 1, 0}, -1.0}}));
    EXPECT_EQ(terms("x / -2"), (Terms{{kX, -0.5}}));
}

TEST(PolynomialParser, Powers) {
    EXPECT_EQ(terms("x^2"), (Terms{{{2, 0, 0}, 1.0}}));
    EXPECT_EQ(terms("x**2"), (Terms{{{2, 0, 0}, 1.0}}));
    EXPECT_EQ(terms("x ^ 2"), (Terms{{{2, 0, 0}, 1.0}}));
    EXPECT_EQ(terms("x^0"), (Terms{{k1, 1.0}}));
    EXPECT_EQ(terms("0^0"), (Terms{{k1, 1.0}}));
    EXPECT_EQ(terms("2^3"), (Terms{{k1, 8.0}}));
    EXPECT_EQ(terms("(x + 1)^2"), (Terms{{{2, 0, 0}, 1.0}, {kX, 2.0}, {k1, 1.0}}));
    EXPECT_EQ(terms("(x^2)^2"), (Terms{{{4, 0, 0}, 1.0}}));
    // Constant exponent expressions.
    EXPECT_EQ(terms("x^(1+1)"), (Terms{{{2, 0, 0}, 1.0}}));
    EXPECT_EQ(terms("x^n"), (Terms{{{2, 0, 0}, 1.0}}));
    EXPECT_EQ(terms("x^(n+1)"), (Terms{{{3, 0, 0}, 1.0}}));
    EXPECT_EQ(terms("x^(6/3)"), (Terms{{{2, 0, 0}, 1.0}}));
    EXPECT_EQ(terms("x^(2*pi/pi)"), (Terms{{{2, 0, 0}, 1.0}}));
    EXPECT_EQ(terms("x^-0"), (Terms{{k1, 1.0}}));
}

TEST(PolynomialParser, PowerIsRightAssociative) {
    EXPECT_EQ(terms("2^3^2"), (Terms{{k1, 512.0}}));  // not (2^3)^2 = 64
    EXPECT_EQ(terms("2**3**2"), (Terms{{k1, 512.0}}));
    EXPECT_EQ(terms("x^1^2"), (Terms{{kX, 1.0}}));  // not (x^1)^2
}

TEST(PolynomialParser, PowerBindsTighterThanUnaryMinus) {
    EXPECT_EQ(terms("-x^2"), (Terms{{{2, 0, 0}, -1.0}}));
    EXPECT_EQ(terms("-2^2"), (Terms{{k1, -4.0}}));
    EXPECT_EQ(terms("(-2)^2"), (Terms{{k1, 4.0}}));
    EXPECT_EQ(terms("(-x)^2"), (Terms{{{2, 0, 0}, 1.0}}));
    EXPECT_EQ(terms("1 - x^2"), (Terms{{k1, 1.0}, {{2, 0, 0}, -1.0}}));
}

TEST(PolynomialParser, ImplicitMultiplication) {
    EXPECT_EQ(terms("2x"), (Terms{{kX, 2.0}}));
    EXPECT_EQ(terms("2 x"), (Terms{{kX, 2.0}}));
    EXPECT_EQ(terms("2.5e1x"), (Terms{{kX, 25.0}}));
    EXPECT_EQ(terms("2x^2"), (Terms{{{2, 0, 0}, 2.0}}));  // 2(x^2), not (2x)^2
    EXPECT_EQ(terms("2(x + 1)"), (Terms{{kX, 2.0}, {k1, 2.0}}));
    EXPECT_EQ(terms("3(x + 1)^2"), (Terms{{{2, 0, 0}, 3.0}, {kX, 6.0}, {k1, 3.0}}));
    EXPECT_EQ(terms("(x + 1)(x - 1)"), (Terms{{{2, 0, 0}, 1.0}, {k1, -1.0}}));
    EXPECT_EQ(terms("(x + 1) (x - 1)"), (Terms{{{2, 0, 0}, 1.0}, {k1, -1.0}}));
    EXPECT_EQ(terms("(x + 1)y"), (Terms{{{1, 1, 0}, 1.0}, {kY, 1.0}}));
    EXPECT_EQ(terms("4R^2(x^2 + y^2)"), (Terms{{{2, 0, 0}, 16.0}, {{0, 2, 0}, 16.0}}));
    EXPECT_EQ(terms("x^2y"), (Terms{{{2, 1, 0}, 1.0}}));
    // Same precedence as '*', left to right: (1/2)x.
    EXPECT_EQ(terms("1/2x"), (Terms{{kX, 0.5}}));
    // An exponent part needs digits, so this is 2 times the constant e.
    EXPECT_EQ(terms(parse_polynomial("2e", {{"e", 3.0}})), (Terms{{k1, 6.0}}));
    EXPECT_EQ(terms(parse_polynomial("2e2", {{"e", 3.0}})), (Terms{{k1, 200.0}}));
}

TEST(PolynomialParser, Whitespace) {
    EXPECT_EQ(terms(" \t x \n +\r\n 1 \f\v"), (Terms{{kX, 1.0}, {k1, 1.0}}));
    EXPECT_EQ(terms("( x ) ^ 2 *  y"), (Terms{{{2, 1, 0}, 1.0}}));
}

TEST(PolynomialParser, ExactCancellationAllowsHighIntermediates) {
    // (x^2+1)^3 = x^6 + 3x^4 + 3x^2 + 1: degree 6 on the way, 2 in the end.
    EXPECT_EQ(terms("(x^2+1)^3 - x^6 - 3x^4"), (Terms{{{2, 0, 0}, 3.0}, {k1, 1.0}}));
    EXPECT_EQ(terms("(x + 1)^5 - x^5 - 5x^4"),
              (Terms{{{3, 0, 0}, 10.0}, {{2, 0, 0}, 10.0}, {kX, 5.0}, {k1, 1.0}}));
    EXPECT_EQ(terms("(x + y + z)^16 - (x + y + z)^16 + z"), (Terms{{kZ, 1.0}}));
    EXPECT_EQ(terms("x - x"), Terms{});
}

TEST(PolynomialParser, TorusMatchesHandExpansion) {
    // With s = x^2+y^2+z^2 and c = R^2-r^2 = 3.75: (s + c)^2 - 16(x^2+y^2)
    //   = s^2 + 2cs + c^2 - 16x^2 - 16y^2. Every coefficient is exact in binary.
    const Terms expected = {
        {{4, 0, 0}, 1.0}, {{0, 4, 0}, 1.0},  {{0, 0, 4}, 1.0},  {{2, 2, 0}, 2.0}, {{2, 0, 2}, 2.0},
        {{0, 2, 2}, 2.0}, {{2, 0, 0}, -8.5}, {{0, 2, 0}, -8.5}, {{0, 0, 2}, 7.5}, {k1, 14.0625},
    };
    const std::map<std::string, double> c = {{"R", 2.0}, {"r", 0.5}};
    EXPECT_EQ(terms(parse_polynomial("(x^2+y^2+z^2+R^2-r^2)^2 - 4*R^2*(x^2+y^2)", c)), expected);
    EXPECT_EQ(terms(parse_polynomial("(x^2+y^2+z^2+R^2-r^2)^2 - 4R^2(x^2+y^2)", c)), expected);
    EXPECT_EQ(parse_polynomial("(x^2+y^2+z^2+R^2-r^2)**2 - 4R**2 (x**2+y**2)", c).degree(), 4);
}

}  // namespace
}  // namespace lat
