// Every class of polynomial parse error, with its message and 1-based column.
#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <string>

#include "geometry/name_suggestion.h"
#include "geometry/polynomial_parser.h"

namespace lat {
namespace {

const std::map<std::string, double> kConstants = {{"R", 2.0}, {"half", 0.5}, {"radius", 1.5}};

void expect_error(std::string_view text, std::size_t column, const std::string& message,
                  const std::map<std::string, double>& constants = kConstants) {
    SCOPED_TRACE(std::string("text: \"") + std::string(text) + "\"");
    try {
        const Poly3 p = parse_polynomial(text, constants);
        ADD_FAILURE() << "no error, got " << p.to_string();
    } catch (const PolynomialParseError& e) {
        EXPECT_EQ(std::string(e.what()), message);
        EXPECT_EQ(e.column(), column);
    }
}

TEST(PolynomialParserErrors, Empty) {
    expect_error("", 1, "empty polynomial");
    expect_error(" \t\n ", 1, "empty polynomial");
}

TEST(PolynomialParserErrors, BadCharacters) {
    expect_error("x # 2", 3, "unexpected character '#'");
    expect_error("x+\xc3\xa9", 3, "unexpected byte 0xc3");
    expect_error("x + . + 1", 5, "unexpected character '.'");
}

TEST(PolynomialParserErrors, NumberOutOfRange) {
    expect_error("x + 1e999", 5, "number '1e999' is out of range");
}

TEST(PolynomialParserErrors, UnknownNames) {
    expect_error("2 * q", 5, "unknown name 'q'");
    expect_error("x + xy", 5, "unknown name 'xy' (did you mean 'x*y'?)");
    expect_error("Rz", 1, "unknown name 'Rz' (did you mean 'R*z'?)");
    expect_error("1 + PI", 5, "unknown name 'PI' (did you mean 'pi'?)");
    expect_error("raduis*x", 1, "unknown name 'raduis' (did you mean 'radius'?)");
    // No exponent part without digits: this is the name e.
    expect_error("2e", 2, "unknown name 'e'");
    // Names are case sensitive.
    expect_error("X", 1, "unknown name 'X' (did you mean 'x'?)");
}

TEST(PolynomialParserErrors, UnbalancedParentheses) {
    expect_error("(x+1", 5, "expected ')' to close '(' at column 1");
    expect_error("2*((x+1)", 9, "expected ')' to close '(' at column 3");
    expect_error("(x+1 2)", 6, "missing operator between '1' and '2'");
    expect_error(")", 1, "unexpected ')'");
    expect_error("x)", 2, "unexpected ')'");
    expect_error("()", 2, "unexpected ')'");
}

TEST(PolynomialParserErrors, MissingOperand) {
    expect_error("x+", 3, "unexpected end of text");
    expect_error("x^", 3, "unexpected end of text");
    expect_error("x**", 4, "unexpected end of text");
    expect_error("-", 2, "unexpected end of text");
    expect_error("x + * y", 5, "unexpected '*'");
    expect_error("x* *2", 4, "unexpected '*'");
    expect_error("x^/2", 3, "unexpected '/'");
}

TEST(PolynomialParserErrors, MissingOperator) {
    expect_error("2 3", 3, "missing operator between '2' and '3'");
    expect_error("x y", 3, "missing operator between 'x' and 'y'");
    expect_error("R(x+1)", 2, "missing operator between 'R' and '('");
    expect_error("(x)2", 4, "missing operator between ')' and '2'");
    expect_error("x^2 3", 5, "missing operator between '2' and '3'");
}

TEST(PolynomialParserErrors, Division) {
    expect_error("x/y", 2, "division by an expression in x, y or z");
    expect_error("1 / (x + 1)", 3, "division by an expression in x, y or z");
    expect_error("x/0", 2, "division by zero");
    expect_error("x/(R-2)", 2, "division by zero");
    expect_error("x/(y-y)", 2, "division by zero");
}

TEST(PolynomialParserErrors, Exponents) {
    expect_error("x^2.5", 3, "exponent must be a non-negative integer, got 2.5");
    expect_error("x^-1", 3, "exponent must be a non-negative integer, got -1");
    expect_error("x ** (1/2)", 6, "exponent must be a non-negative integer, got 0.5");
    expect_error("x^half", 3, "exponent must be a non-negative integer, got 0.5");
    expect_error("2^-1", 3, "exponent must be a non-negative integer, got -1");
    expect_error("x^y", 3, "exponent must not depend on x, y or z");
    expect_error("x^(y-y+x)", 3, "exponent must not depend on x, y or z");
}

TEST(PolynomialParserErrors, IntermediateDegreeCap) {
    expect_error("(x+y+z)^1000", 8, "intermediate degree 1000 is over the limit of 16");
    expect_error("(x+1)^17", 6, "intermediate degree 17 is over the limit of 16");
    expect_error("x^1e300", 2, "intermediate degree 1e+300 is over the limit of 16");
    expect_error("x^9*x^8", 4, "intermediate degree 17 is over the limit of 16");
    expect_error("2x^9 (x^8)", 6, "intermediate degree 17 is over the limit of 16");
    expect_error("(x^2+1)^9 - (x^2+1)^9", 8, "intermediate degree 18 is over the limit of 16");
}

TEST(PolynomialParserErrors, FinalDegreeOverFour) {
    expect_error("x^5", 1, "degree 5 (term x^5) is over 4");
    expect_error("x^16", 1, "degree 16 (term x^16) is over 4");
    expect_error("1 + 3*x^2*y^3", 1, "degree 5 (term 3*x^2*y^3) is over 4");
    // Among the terms of top degree the one with the most x, then y, is shown.
    expect_error("x^3*y^3 - 2*x^6 + z^6", 1, "degree 6 (term -2*x^6) is over 4");
    // Cancellation is exact, so a rounding residue shows with its coefficient.
    expect_error("0.1*3*x^5 - 0.3*x^5", 1, "degree 5 (term 5.55112e-17*x^5) is over 4");
}

TEST(PolynomialParserErrors, Overflow) {
    expect_error("1e200*1e200*x", 6, "coefficient overflow");
    expect_error("x + 1e308 + 1e308", 11, "coefficient overflow");
    expect_error("10^400", 3, "coefficient overflow");
}

TEST(PolynomialParserErrors, BadConstants) {
    const double inf = std::numeric_limits<double>::infinity();
    expect_error("x + bad", 5, "constant 'bad' is not finite", {{"bad", inf}});
    expect_error("x + 1", 1, "constant 'y' clashes with the variable y", {{"y", 1.0}});
}

TEST(PolynomialParserErrors, NestingLimit) {
    const std::string ok = std::string(200, '(') + "x" + std::string(200, ')');
    EXPECT_EQ(parse_polynomial(ok, kConstants).degree(), 1);
    const std::string deep = std::string(300, '(') + "x" + std::string(300, ')');
    expect_error(deep, 257, "too deeply nested");
    // Unary operators nest too (kept within the length limit, which a longer text hits first).
    expect_error(std::string(kMaxPolynomialLength - 1, '-') + "x", 257, "too deeply nested");
}

// Within the length limit, expansion could still take seconds: its work is bounded too.
TEST(PolynomialParserErrors, ExpansionWorkLimit) {
    std::string heavy;
    while (heavy.size() < 9000) heavy += "(x+y+z+1)^16 - ";
    heavy += "x";
    try {
        parse_polynomial(heavy, kConstants);
        ADD_FAILURE() << "no error";
    } catch (const PolynomialParseError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "too much to expand (over 5000000 term products); simplify the polynomial");
    }
    // A long but ordinary quartic is far within the limit.
    std::string sum;
    for (int i = 0; i < 100; ++i) sum += "(x^2+y^2+z^2+R^2-half^2)^2 - 4*R^2*(x^2+y^2) + ";
    EXPECT_EQ(parse_polynomial(sum + "1", kConstants).degree(), 4);
}

TEST(PolynomialParserErrors, LengthLimit) {
    const std::string ok = "x" + std::string(kMaxPolynomialLength - 1, ' ');
    EXPECT_EQ(parse_polynomial(ok, kConstants).degree(), 1);
    expect_error(ok + " ", kMaxPolynomialLength + 1,
                 "the text is 10001 characters long, over the limit of 10000");
    expect_error(std::string(100000, '-') + "x", kMaxPolynomialLength + 1,
                 "the text is 100001 characters long, over the limit of 10000");
}

TEST(PolynomialSuggestName, Hints) {
    const std::vector<std::string> known = {"x", "y", "z", "pi", "R", "radius", "not a name"};
    EXPECT_EQ(suggest_name("xy", known), "x*y");
    EXPECT_EQ(suggest_name("xyz", known), "x*y*z");
    EXPECT_EQ(suggest_name("xx", known), "x*x");
    EXPECT_EQ(suggest_name("pix", known), "pi*x");
    EXPECT_EQ(suggest_name("Rx", known), "R*x");
    EXPECT_EQ(suggest_name("PI", known), "pi");
    EXPECT_EQ(suggest_name("r", known), "R");
    EXPECT_EQ(suggest_name("radus", known), "radius");
    EXPECT_EQ(suggest_name("raduis", known), "radius");
    EXPECT_EQ(suggest_name("q", known), "");  // one letter off is not a typo of another
    EXPECT_EQ(suggest_name("abc", known), "");
    EXPECT_EQ(suggest_name("notaname", known), "");  // non-identifiers are never suggested
}

}  // namespace
}  // namespace lat
