// Recursive descent over a token list; the grammar is in docs/polynomial-syntax.md.
// Every value is a SparsePoly (constants are degree-0 polynomials), so constant folding and
// expansion are the same arithmetic.
#include "geometry/polynomial_parser.h"

#include <charconv>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "geometry/name_suggestion.h"
#include "geometry/sparse_poly.h"
#include "util/error.h"

namespace lat {
namespace {

// Intermediates may exceed degree 4, but not this: it stops (x+y+z)^1000 from exploding.
constexpr int kMaxIntermediateDegree = 16;
// Guards the stack against absurd nesting such as 100000 opening parentheses.
constexpr int kMaxNesting = 256;
// Bounds the cost of expansion, counted in term products (an m-term times an n-term polynomial
// costs m * n): about 0.15 s. Real quartics need a few hundred; without a bound, 10,000
// characters of "(x+y+z+1)^16 - ..." took seconds, and a scene may hold many polynomials.
constexpr double kMaxExpansionWork = 5e6;

enum class Tok { kNumber, kName, kPlus, kMinus, kStar, kSlash, kCaret, kLParen, kRParen, kEnd };

struct Token {
    Tok kind;
    std::string_view text;
    std::size_t column;  // 1-based
    double value = 0.0;  // for numbers
};

void append(std::string& out, char c) {
    out.push_back(c);
}
void append(std::string& out, std::string_view s) {
    out.append(s);
}

// Concatenation by append: "literal" + std::string&& trips a GCC 12 -Wrestrict false positive.
template <class... Parts>
std::string cat(const Parts&... parts) {
    std::string out;
    (append(out, parts), ...);
    return out;
}

[[noreturn]] void fail(std::size_t column, const std::string& message) {
    throw PolynomialParseError(column, message);
}

// Non-printable bytes show as hex, e.g. "0xc3".
std::string format_byte(char c) {
    const char* hex = "0123456789abcdef";
    const auto b = static_cast<unsigned char>(c);
    return {'0', 'x', hex[b >> 4], hex[b & 15]};
}

bool is_digit(char c) {
    return c >= '0' && c <= '9';
}
bool is_name_start(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
bool is_name_char(char c) {
    return is_name_start(c) || is_digit(c);
}
bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

// Length of the number at the start of s, or 0. An exponent part is taken only when digits
// follow, so "2e" is 2 then the name e, while "2e3" is 2000.
std::size_t number_length(std::string_view s) {
    std::size_t n = 0;
    while (n < s.size() && is_digit(s[n])) ++n;
    const std::size_t int_digits = n;
    if (n < s.size() && s[n] == '.') {
        std::size_t f = n + 1;
        while (f < s.size() && is_digit(s[f])) ++f;
        if (int_digits == 0 && f == n + 1) return 0;  // a lone '.'
        n = f;
    }
    if (n == 0) return 0;
    if (n < s.size() && (s[n] == 'e' || s[n] == 'E')) {
        std::size_t e = n + 1;
        if (e < s.size() && (s[e] == '+' || s[e] == '-')) ++e;
        if (e < s.size() && is_digit(s[e])) {
            while (e < s.size() && is_digit(s[e])) ++e;
            n = e;
        }
    }
    return n;
}

std::vector<Token> tokenize(std::string_view text) {
    std::vector<Token> tokens;
    std::size_t i = 0;
    while (i < text.size()) {
        const char c = text[i];
        const std::size_t column = i + 1;
        if (is_space(c)) {
            ++i;
            continue;
        }
        if (const std::size_t len = number_length(text.substr(i)); len > 0) {
            const std::string_view s = text.substr(i, len);
            double v = 0.0;
            const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
            if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v))
                fail(column, cat("number '", s, "' is out of range"));
            tokens.push_back({Tok::kNumber, s, column, v});
            i += len;
            continue;
        }
        if (is_name_start(c)) {
            std::size_t len = 1;
            while (i + len < text.size() && is_name_char(text[i + len])) ++len;
            tokens.push_back({Tok::kName, text.substr(i, len), column});
            i += len;
            continue;
        }
        Tok kind;
        std::size_t len = 1;
        switch (c) {
            case '+':
                kind = Tok::kPlus;
                break;
            case '-':
                kind = Tok::kMinus;
                break;
            case '/':
                kind = Tok::kSlash;
                break;
            case '^':
                kind = Tok::kCaret;
                break;
            case '(':
                kind = Tok::kLParen;
                break;
            case ')':
                kind = Tok::kRParen;
                break;
            case '*':
                // "**" is a synonym of "^".
                if (i + 1 < text.size() && text[i + 1] == '*') {
                    kind = Tok::kCaret;
                    len = 2;
                } else {
                    kind = Tok::kStar;
                }
                break;
            default:
                if (c > ' ' && c < 127) fail(column, cat("unexpected character '", c, "'"));
                fail(column, cat("unexpected byte ", format_byte(c)));
        }
        tokens.push_back({kind, text.substr(i, len), column});
        i += len;
    }
    tokens.push_back({Tok::kEnd, {}, text.size() + 1});
    return tokens;
}

std::string describe(const Token& t) {
    return t.kind == Tok::kEnd ? "end of text" : cat("'", t.text, "'");
}

bool starts_operand(Tok k) {
    return k == Tok::kNumber || k == Tok::kName || k == Tok::kLParen;
}

class Parser {
public:
    Parser(std::vector<Token> tokens, const std::map<std::string, double>& constants)
        : toks_(std::move(tokens)), constants_(constants) {}

    SparsePoly parse() {
        SparsePoly p = parse_sum();
        if (peek().kind != Tok::kEnd) fail(peek().column, cat("unexpected ", describe(peek())));
        return p;
    }

private:
    const Token& peek() const { return toks_[pos_]; }
    const Token& take() { return toks_[pos_ == toks_.size() - 1 ? pos_ : pos_++]; }

    // sum := product (('+' | '-') product)*
    SparsePoly parse_sum() {
        SparsePoly p = parse_product();
        while (peek().kind == Tok::kPlus || peek().kind == Tok::kMinus) {
            const Token& op = take();
            const SparsePoly q = parse_product();
            p = op.kind == Tok::kPlus ? p + q : p - q;
            check_finite(p, op);
        }
        return p;
    }

    // product := unary (('*' | '/') unary | implicit power)*
    SparsePoly parse_product() {
        SparsePoly p = parse_unary();
        for (;;) {
            const Token& op = peek();
            if (op.kind == Tok::kStar) {
                take();
                p = multiply(p, parse_unary(), op);
            } else if (op.kind == Tok::kSlash) {
                take();
                p = divide(p, parse_unary(), op);
            } else if (starts_operand(op.kind)) {
                // Implicit multiplication: only after a number or ')', and not before a number,
                // so that "2x" and "(x+1)(x-1)" work while "xy" or "x 2" stay mistakes.
                const Token& prev = toks_[pos_ - 1];
                const bool after_ok = prev.kind == Tok::kNumber || prev.kind == Tok::kRParen;
                if (!after_ok || op.kind == Tok::kNumber)
                    fail(op.column,
                         cat("missing operator between ", describe(prev), " and ", describe(op)));
                p = multiply(p, parse_power(), op);
            } else {
                return p;
            }
        }
    }

    // unary := ('+' | '-') unary | power. Unary minus binds looser than '^': -x^2 is -(x^2).
    SparsePoly parse_unary() {
        if (++depth_ > kMaxNesting) fail(peek().column, "too deeply nested");
        SparsePoly p;
        if (peek().kind == Tok::kPlus) {
            take();
            p = parse_unary();
        } else if (peek().kind == Tok::kMinus) {
            take();
            p = -parse_unary();
        } else {
            p = parse_power();
        }
        --depth_;
        return p;
    }

    // power := primary (('^' | '**') unary)?  Right-associative through unary -> power.
    SparsePoly parse_power() {
        SparsePoly base = parse_primary();
        if (peek().kind != Tok::kCaret) return base;
        const Token& op = take();
        const std::size_t exponent_column = peek().column;
        const SparsePoly e = parse_unary();
        if (!e.is_constant()) fail(exponent_column, "exponent must not depend on x, y or z");
        const double v = e.constant_term();
        const double n = std::round(v);
        // A tolerance, so that exponents like 6/3 or 2*pi/pi still count as integers.
        if (!std::isfinite(v) || n < 0.0 || std::abs(v - n) > 1e-9)
            fail(exponent_column,
                 cat("exponent must be a non-negative integer, got ", format_number(v, 15)));
        SparsePoly result;
        if (base.is_constant()) {
            result = SparsePoly::constant(std::pow(base.constant_term(), n));
        } else {
            const double degree = base.degree() * n;
            if (degree > kMaxIntermediateDegree) fail_degree(degree, op);
            // Repeated squaring does at most n products, none bigger than base x result.
            const double result_terms = (degree + 1) * (degree + 2) * (degree + 3) / 6;
            charge(n * static_cast<double>(base.terms().size()) * result_terms, op);
            result = pow(base, static_cast<int>(n));
        }
        check_finite(result, op);
        return result;
    }

    // primary := number | name | '(' sum ')'
    SparsePoly parse_primary() {
        const Token& t = take();
        switch (t.kind) {
            case Tok::kNumber:
                return SparsePoly::constant(t.value);
            case Tok::kName:
                return lookup(t);
            case Tok::kLParen: {
                SparsePoly p = parse_sum();
                if (peek().kind != Tok::kRParen)
                    fail(peek().column,
                         cat("expected ')' to close '(' at column ", std::to_string(t.column)));
                take();
                return p;
            }
            default:
                fail(t.column, cat("unexpected ", describe(t)));
        }
    }

    SparsePoly lookup(const Token& t) {
        const std::string name(t.text);
        if (name == "x") return SparsePoly::variable(0);
        if (name == "y") return SparsePoly::variable(1);
        if (name == "z") return SparsePoly::variable(2);
        if (const auto it = constants_.find(name); it != constants_.end()) {
            if (!std::isfinite(it->second))
                fail(t.column, cat("constant '", name, "' is not finite"));
            return SparsePoly::constant(it->second);
        }
        if (name == "pi") return SparsePoly::constant(std::numbers::pi);
        std::vector<std::string> known = {"x", "y", "z", "pi"};
        for (const auto& [k, v] : constants_) known.push_back(k);
        std::string message = cat("unknown name '", name, "'");
        if (const std::string hint = suggest_name(name, known); !hint.empty())
            message += cat(" (did you mean '", hint, "'?)");
        fail(t.column, message);
    }

    SparsePoly multiply(const SparsePoly& f, const SparsePoly& g, const Token& op) {
        if (f.degree() >= 0 && g.degree() >= 0 && f.degree() + g.degree() > kMaxIntermediateDegree)
            fail_degree(f.degree() + g.degree(), op);
        charge(static_cast<double>(f.terms().size()) * static_cast<double>(g.terms().size()), op);
        SparsePoly h = f * g;
        check_finite(h, op);
        return h;
    }

    void charge(double work, const Token& op) {
        work_ += work;
        if (work_ > kMaxExpansionWork)
            fail(op.column, cat("too much to expand (over ", format_number(kMaxExpansionWork, 15),
                                " term products); simplify the polynomial"));
    }

    SparsePoly divide(const SparsePoly& f, const SparsePoly& g, const Token& op) {
        if (!g.is_constant()) fail(op.column, "division by an expression in x, y or z");
        if (g.constant_term() == 0.0) fail(op.column, "division by zero");
        SparsePoly h = f / g.constant_term();
        check_finite(h, op);
        return h;
    }

    [[noreturn]] static void fail_degree(double degree, const Token& op) {
        fail(op.column, cat("intermediate degree ", format_number(degree, 15),
                            " is over the limit of ", std::to_string(kMaxIntermediateDegree)));
    }

    static void check_finite(const SparsePoly& p, const Token& op) {
        if (!p.is_finite()) fail(op.column, "coefficient overflow");
    }

    std::vector<Token> toks_;
    const std::map<std::string, double>& constants_;
    std::size_t pos_ = 0;
    int depth_ = 0;
    double work_ = 0.0;  // term products so far, see kMaxExpansionWork
};

std::string monomial_string(const Monomial& m) {
    static const char* names[3] = {"x", "y", "z"};
    std::string out;
    for (std::size_t v = 0; v < 3; ++v) {
        if (m[v] == 0) continue;
        if (!out.empty()) out += '*';
        out += names[v];
        if (m[v] > 1) out += cat("^", std::to_string(m[v]));
    }
    return out;
}

// E.g. "x^6", "-y^2*z^4" or "1e-16*x^5": the coefficient shows when a rounding residue is
// what failed to cancel.
std::string term_string(const Monomial& m, double c) {
    if (c == 1.0) return monomial_string(m);
    if (c == -1.0) return cat("-", monomial_string(m));
    return cat(format_number(c, 6), "*", monomial_string(m));
}

}  // namespace

Poly3 parse_polynomial(std::string_view text, const std::map<std::string, double>& constants) {
    if (text.size() > kMaxPolynomialLength)
        fail(kMaxPolynomialLength + 1,
             cat("the text is ", std::to_string(text.size()),
                 " characters long, over the limit of ", std::to_string(kMaxPolynomialLength)));
    for (const char* v : {"x", "y", "z"})
        if (constants.count(v)) fail(1, cat("constant '", v, "' clashes with the variable ", v));
    std::vector<Token> tokens = tokenize(text);
    if (tokens.size() == 1) fail(1, "empty polynomial");
    const SparsePoly p = Parser(std::move(tokens), constants).parse();

    // Report a term of the highest degree; among those, the one with the most x, then y.
    const Monomial* worst = nullptr;
    double worst_c = 0.0;
    for (const auto& [m, c] : p.terms())
        if (!worst || total_degree(m) > total_degree(*worst) ||
            (total_degree(m) == total_degree(*worst) && m > *worst)) {
            worst = &m;
            worst_c = c;
        }
    if (worst && total_degree(*worst) > Poly3::kMaxDegree)
        fail(1, cat("degree ", std::to_string(total_degree(*worst)), " (term ",
                    term_string(*worst, worst_c), ") is over ", std::to_string(Poly3::kMaxDegree)));

    Poly3 out;
    for (const auto& [m, c] : p.terms()) out.at(m[0], m[1], m[2]) = c;
    return out;
}

}  // namespace lat
