// Random expression trees, printed with as few parentheses as the documented precedence allows
// (and some extra ones, spaces, "**" and implicit products), parsed, and the Poly3 evaluated at
// random points against a direct evaluation of the tree. The printer is an independent statement
// of the precedence rules in docs/polynomial-syntax.md.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <initializer_list>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <string_view>
#include <utility>

#include "geometry/polynomial_parser.h"

namespace lat {
namespace {

// Names that start with 'e' would merge with a preceding number ("2e3"), so none do.
const std::map<std::string, double> kConstants = {{"R", 2.0}, {"r", 0.5}, {"k", 3.0}};

// By append, left to right: "literal" + std::string&& trips a GCC 12 -Wrestrict false positive,
// and the order matters because the parts draw from the random generator.
std::string cat(std::initializer_list<std::string_view> parts) {
    std::string out;
    for (const std::string_view part : parts) out.append(part);
    return out;
}

struct Node;
using NodePtr = std::shared_ptr<const Node>;

struct Node {
    enum Kind { kNumber, kVariable, kConstant, kAdd, kSub, kMul, kDiv, kNeg, kPow } kind;
    std::string text;  // numbers and names
    double value = 0;  // numbers and constants
    int var = 0;       // variables
    int exponent = 0;  // kPow
    NodePtr a, b;
};

double eval(const Node& n, const double p[3]) {
    switch (n.kind) {
        case Node::kNumber:
        case Node::kConstant:
            return n.value;
        case Node::kVariable:
            return p[n.var];
        case Node::kAdd:
            return eval(*n.a, p) + eval(*n.b, p);
        case Node::kSub:
            return eval(*n.a, p) - eval(*n.b, p);
        case Node::kMul:
            return eval(*n.a, p) * eval(*n.b, p);
        case Node::kDiv:
            return eval(*n.a, p) / eval(*n.b, p);
        case Node::kNeg:
            return -eval(*n.a, p);
        case Node::kPow:
            return std::pow(eval(*n.a, p), n.exponent);
    }
    return 0;
}

// The same with every sum turned into a sum of magnitudes: the scale for rounding errors.
double magnitude(const Node& n, const double p[3]) {
    switch (n.kind) {
        case Node::kAdd:
        case Node::kSub:
            return magnitude(*n.a, p) + magnitude(*n.b, p);
        case Node::kMul:
            return magnitude(*n.a, p) * magnitude(*n.b, p);
        case Node::kDiv:
            return magnitude(*n.a, p) / std::abs(eval(*n.b, p));
        case Node::kNeg:
            return magnitude(*n.a, p);
        case Node::kPow:
            return std::pow(magnitude(*n.a, p), n.exponent);
        default:
            return std::abs(eval(n, p));
    }
}

class Generator {
public:
    explicit Generator(unsigned seed) : rng_(seed) {}

    // A tree whose polynomial has degree <= max_degree.
    NodePtr tree(int max_degree, int depth) {
        if (depth == 0 || chance(0.2)) return leaf(max_degree);
        auto n = std::make_shared<Node>();
        // Products and powers twice as often as the rest, to reach degree 4 often enough.
        static constexpr Node::Kind kinds[] = {Node::kAdd, Node::kSub, Node::kMul, Node::kMul,
                                               Node::kDiv, Node::kNeg, Node::kPow, Node::kPow};
        n->kind = kinds[pick(8)];
        if (n->kind == Node::kMul) {
            const int left = pick(max_degree + 1);
            n->a = tree(left, depth - 1);
            n->b = tree(max_degree - left, depth - 1);
        } else if (n->kind == Node::kDiv) {
            n->a = tree(max_degree, depth - 1);
            n->b = tree(0, depth - 1);
            const double origin[3] = {0, 0, 0};
            if (std::abs(eval(*n->b, origin)) < 0.25) n->b = number("2", 2.0);
        } else if (n->kind == Node::kPow) {
            n->exponent = pick(5);
            n->a = tree(n->exponent == 0 ? 4 : max_degree / n->exponent, depth - 1);
        } else {
            n->a = tree(max_degree, depth - 1);
            if (n->kind != Node::kNeg) n->b = tree(max_degree, depth - 1);
        }
        return n;
    }

    // A product or power at the root, which more often gives degree 3 or 4.
    NodePtr high_degree_tree(int depth) {
        auto n = std::make_shared<Node>();
        if (chance(0.5)) {
            n->kind = Node::kMul;
            n->a = tree(2, depth);
            n->b = tree(2, depth);
        } else {
            n->kind = Node::kPow;
            n->exponent = 2 + pick(3);
            n->a = tree(4 / n->exponent, depth);
        }
        return n;
    }

    // Text and precedence: 1 sum, 2 product, 3 unary minus, 4 power, 5 atom.
    std::pair<std::string, int> print(const Node& n) {
        switch (n.kind) {
            case Node::kNumber:
            case Node::kConstant:
            case Node::kVariable:
                return {n.text, 5};
            case Node::kNeg:
                return {cat({"-", space(), operand(*n.a, 3)}), 3};
            case Node::kAdd:
            case Node::kSub: {
                const char* op = n.kind == Node::kAdd ? "+" : "-";
                return {cat({operand(*n.a, 1), space(), op, space(), operand(*n.b, 2)}), 1};
            }
            case Node::kMul:
            case Node::kDiv: {
                const std::string left = operand(*n.a, 2), right = operand(*n.b, 3);
                const bool implicit = n.kind == Node::kMul && can_juxtapose(left, right);
                const char* op = n.kind == Node::kDiv ? "/" : implicit ? "" : "*";
                return {cat({left, space(), op, space(), right}), 2};
            }
            case Node::kPow: {
                const char* op = chance(0.3) ? "**" : "^";
                return {cat({operand(*n.a, 5), space(), op, space(), exponent(n.exponent)}), 4};
            }
        }
        return {};
    }

private:
    bool chance(double p) { return std::uniform_real_distribution<double>(0, 1)(rng_) < p; }
    int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }

    static NodePtr number(const std::string& text, double value) {
        auto n = std::make_shared<Node>();
        n->kind = Node::kNumber;
        n->text = text;
        n->value = value;
        return n;
    }

    NodePtr leaf(int max_degree) {
        auto n = std::make_shared<Node>();
        // Mostly variables where allowed, or most trees come out constant.
        const int choice = max_degree > 0 && chance(0.6) ? 2 : pick(2);
        if (choice == 0) {
            static const std::pair<const char*, double> numbers[] = {
                {"2", 2.0},       {"0.5", 0.5},  {".25", 0.25}, {"3", 3.0},   {"1.5", 1.5},
                {"2.5e-1", 0.25}, {"1E1", 10.0}, {"7", 7.0},    {"0.1", 0.1}, {"4.", 4.0}};
            const auto& [text, value] = numbers[pick(10)];
            return number(text, value);
        }
        if (choice == 1) {
            auto it = kConstants.begin();
            std::advance(it, pick(static_cast<int>(kConstants.size())));
            n->kind = Node::kConstant;
            n->text = it->first;
            n->value = it->second;
        } else {
            n->kind = Node::kVariable;
            n->var = pick(3);
            n->text = std::string(1, static_cast<char>('x' + n->var));
        }
        return n;
    }

    std::string space() { return chance(0.3) ? " " : ""; }

    // Parenthesised when its precedence is below min_prec, and sometimes anyway.
    std::string operand(const Node& n, int min_prec) {
        auto [text, prec] = print(n);
        if (prec < min_prec || chance(0.1)) return cat({"(", space(), text, space(), ")"});
        return text;
    }

    // Implicit multiplication: after a number or ')', before a name or '('.
    static bool can_juxtapose(const std::string& left, const std::string& right) {
        const char l = left.back(), r = right.front();
        return (std::isdigit(static_cast<unsigned char>(l)) || l == '.' || l == ')') &&
               (std::isalpha(static_cast<unsigned char>(r)) || r == '(');
    }

    // An exponent of value e, in one of several constant forms.
    std::string exponent(int e) {
        switch (pick(4)) {
            case 0:
                return cat({"(", std::to_string(e - 1), "+1)"});
            case 1:
                return e == 3 ? "k" : std::to_string(e);
            case 2:
                return e == 1 ? "1^3" : cat({std::to_string(e), "^1"});  // right-associative
            default:
                return std::to_string(e);
        }
    }

    std::mt19937 rng_;
};

TEST(PolynomialParserRandom, MatchesDirectEvaluation) {
    Generator gen(20261121);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> coord(-2.0, 2.0);
    int checked = 0;
    for (int trial = 0; trial < 10000; ++trial) {
        const int depth = 2 + trial % 5;
        const NodePtr tree = trial % 3 == 0 ? gen.high_degree_tree(depth) : gen.tree(4, depth);
        const std::string text = gen.print(*tree).first;
        SCOPED_TRACE(cat({"text: \"", text, "\""}));
        Poly3 p;
        try {
            p = parse_polynomial(text, kConstants);
        } catch (const PolynomialParseError& e) {
            FAIL() << "column " << e.column() << ": " << e.what();
        }
        for (int i = 0; i < 4; ++i) {
            const double pt[3] = {coord(rng), coord(rng), coord(rng)};
            const double expected = eval(*tree, pt);
            const double tolerance = 1e-12 * (1.0 + magnitude(*tree, pt));
            ASSERT_NEAR(p.eval({pt[0], pt[1], pt[2]}), expected, tolerance)
                << "at (" << pt[0] << ", " << pt[1] << ", " << pt[2] << ")";
            ++checked;
        }
    }
    EXPECT_EQ(checked, 10000 * 4);
}

}  // namespace
}  // namespace lat
