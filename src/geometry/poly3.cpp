#include "geometry/poly3.h"

#include <cassert>
#include <cmath>
#include <cstdio>
#include <utility>

namespace lat {
namespace {

// Monomials' exponents by dense index: ordered by total degree, then by descending powers of
// x, then of y.
constexpr std::array<std::array<int, 3>, Poly3::kTerms> kExponents = [] {
    std::array<std::array<int, 3>, Poly3::kTerms> e{};
    std::size_t n = 0;
    for (int d = 0; d <= Poly3::kMaxDegree; ++d)
        for (int i = d; i >= 0; --i)
            for (int j = d - i; j >= 0; --j) e[n++] = {i, j, d - i - j};
    return e;
}();
static_assert(kExponents.back() == std::array<int, 3>{0, 0, 4});  // every index filled

// Dense index by exponents.
struct MonomialTable {
    int lookup[5][5][5]{};
    MonomialTable() {
        for (std::size_t n = 0; n < kExponents.size(); ++n) {
            const auto [i, j, k] = kExponents[n];
            lookup[i][j][k] = static_cast<int>(n);
        }
    }
};

const MonomialTable& table() {
    static const MonomialTable t;
    return t;
}

// Coefficients of (o + t d)^n as a polynomial in t, for n = 0..4.
void binomial_powers(double o, double d, double p[5][5]) {
    for (int n = 0; n < 5; ++n)
        for (int k = 0; k < 5; ++k) p[n][k] = 0.0;
    p[0][0] = 1.0;
    for (int n = 1; n <= 4; ++n)
        for (int k = 0; k <= n; ++k)
            p[n][k] = o * p[n - 1][k] + (k > 0 ? d * p[n - 1][k - 1] : 0.0);
}

}  // namespace

int Poly3::index(int i, int j, int k) {
    assert(i >= 0 && j >= 0 && k >= 0 && i + j + k <= kMaxDegree);
    return table().lookup[i][j][k];
}

std::array<int, 3> Poly3::exponents(int n) { return kExponents[static_cast<std::size_t>(n)]; }

int Poly3::degree() const {
    int deg = -1;
    for (int n = 0; n < kTerms; ++n) {
        if (a[static_cast<std::size_t>(n)] == 0.0) continue;
        const auto e = exponents(n);
        deg = std::max(deg, e[0] + e[1] + e[2]);
    }
    return deg;
}

double Poly3::eval(Vec3 p) const {
    double px[5] = {1, p.x, p.x * p.x, p.x * p.x * p.x, p.x * p.x * p.x * p.x};
    double py[5] = {1, p.y, p.y * p.y, p.y * p.y * p.y, p.y * p.y * p.y * p.y};
    double pz[5] = {1, p.z, p.z * p.z, p.z * p.z * p.z, p.z * p.z * p.z * p.z};
    double sum = 0.0;
    for (int n = 0; n < kTerms; ++n) {
        const double c = a[static_cast<std::size_t>(n)];
        if (c == 0.0) continue;
        const auto e = exponents(n);
        sum += c * px[e[0]] * py[e[1]] * pz[e[2]];
    }
    return sum;
}

Vec3 Poly3::gradient(Vec3 p) const {
    double px[5] = {1, p.x, p.x * p.x, p.x * p.x * p.x, p.x * p.x * p.x * p.x};
    double py[5] = {1, p.y, p.y * p.y, p.y * p.y * p.y, p.y * p.y * p.y * p.y};
    double pz[5] = {1, p.z, p.z * p.z, p.z * p.z * p.z, p.z * p.z * p.z * p.z};
    Vec3 g;
    for (int n = 0; n < kTerms; ++n) {
        const double c = a[static_cast<std::size_t>(n)];
        if (c == 0.0) continue;
        const auto [i, j, k] = exponents(n);
        if (i > 0) g.x += c * i * px[i - 1] * py[j] * pz[k];
        if (j > 0) g.y += c * j * px[i] * py[j - 1] * pz[k];
        if (k > 0) g.z += c * k * px[i] * py[j] * pz[k - 1];
    }
    return g;
}

namespace {

// Term N of f(o + t d): the product of three polynomials in t of degrees i, j, k (i + j + k
// <= 4), added to c. With the degrees known at compile time the loops unroll; the sums are
// taken in the same order as a loop over the terms would (same bits).
template <std::size_t N>
void add_term(double coef, const double px[5][5], const double py[5][5], const double pz[5][5],
              double c[5]) {
    constexpr int i = kExponents[N][0], j = kExponents[N][1], k = kExponents[N][2];
    if (coef == 0.0) return;
    double xy[5] = {0, 0, 0, 0, 0};
    for (int u = 0; u <= i; ++u)
        for (int v = 0; v <= j; ++v) xy[u + v] += px[i][u] * py[j][v];
    for (int uv = 0; uv <= i + j; ++uv)
        for (int w = 0; w <= k; ++w) c[uv + w] += coef * xy[uv] * pz[k][w];
}

template <std::size_t... N>
void add_terms(const std::array<double, Poly3::kTerms>& a, const double px[5][5],
               const double py[5][5], const double pz[5][5], double c[5],
               std::index_sequence<N...>) {
    (add_term<N>(a[N], px, py, pz, c), ...);  // terms 0, 1, ... in order
}

}  // namespace

void Poly3::along_ray(Vec3 o, Vec3 d, double c[5]) const {
    double px[5][5], py[5][5], pz[5][5];
    binomial_powers(o.x, d.x, px);
    binomial_powers(o.y, d.y, py);
    binomial_powers(o.z, d.z, pz);
    for (int m = 0; m < 5; ++m) c[m] = 0.0;
    add_terms(a, px, py, pz, c, std::make_index_sequence<kTerms>{});
}

std::string Poly3::to_string() const {
    std::string out;
    static const char* names[3] = {"x", "y", "z"};
    for (int n = 0; n < kTerms; ++n) {
        const double c = a[static_cast<std::size_t>(n)];
        if (c == 0.0) continue;
        const auto e = exponents(n);
        const bool constant = e[0] + e[1] + e[2] == 0;
        double mag = std::abs(c);
        const char* sign = out.empty() ? (c < 0 ? "-" : "") : (c < 0 ? " - " : " + ");
        out.append(sign);
        char buf[64];
        if (mag != 1.0 || constant) {
            std::snprintf(buf, sizeof buf, "%.17g", mag);
            out += buf;
        }
        bool first = mag == 1.0 && !constant;
        for (int v = 0; v < 3; ++v) {
            if (e[static_cast<std::size_t>(v)] == 0) continue;
            if (!first) out.push_back('*');
            first = false;
            out.append(names[v]);
            if (e[static_cast<std::size_t>(v)] > 1) {
                out.push_back('^');
                out.push_back(static_cast<char>('0' + e[static_cast<std::size_t>(v)]));
            }
        }
    }
    return out.empty() ? "0" : out;
}

Poly3 operator+(const Poly3& f, const Poly3& g) {
    Poly3 h;
    for (std::size_t n = 0; n < Poly3::kTerms; ++n) h.a[n] = f.a[n] + g.a[n];
    return h;
}

Poly3 operator*(double s, const Poly3& f) {
    Poly3 h;
    for (std::size_t n = 0; n < Poly3::kTerms; ++n) h.a[n] = s * f.a[n];
    return h;
}

}  // namespace lat
