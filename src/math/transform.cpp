#include "math/transform.h"

#include <algorithm>
#include <cmath>

namespace lat {

Mat3 operator*(const Mat3& a, const Mat3& b) {
    Mat3 out;
    for (int i = 0; i < 3; ++i) {
        const auto ui = static_cast<std::size_t>(i);
        out.r[ui] = {dot(a.r[ui], b.col(0)), dot(a.r[ui], b.col(1)), dot(a.r[ui], b.col(2))};
    }
    return out;
}

Mat3 transpose(const Mat3& m) { return {{m.col(0), m.col(1), m.col(2)}}; }

double determinant(const Mat3& m) { return dot(m.r[0], cross(m.r[1], m.r[2])); }

std::optional<Mat3> inverse(const Mat3& m) {
    // Columns of the adjugate are cross products of rows.
    const Vec3 c0 = cross(m.r[1], m.r[2]);
    const Vec3 c1 = cross(m.r[2], m.r[0]);
    const Vec3 c2 = cross(m.r[0], m.r[1]);
    const double det = dot(m.r[0], c0);
    // Singular relative to scale: |det| against the product of row lengths (Hadamard bound).
    const double scale = length(m.r[0]) * length(m.r[1]) * length(m.r[2]);
    if (!std::isfinite(det) || scale == 0.0 || std::abs(det) <= 1e-12 * scale) return std::nullopt;
    const double inv = 1.0 / det;
    Mat3 out;
    out.r[0] = {c0.x * inv, c1.x * inv, c2.x * inv};
    out.r[1] = {c0.y * inv, c1.y * inv, c2.y * inv};
    out.r[2] = {c0.z * inv, c1.z * inv, c2.z * inv};
    return out;
}

Mat3 rotation(Vec3 axis, double angle) {
    const Vec3 a = normalize(axis);
    const double c = std::cos(angle), s = std::sin(angle), k = 1.0 - c;
    return {{Vec3{c + a.x * a.x * k, a.x * a.y * k - a.z * s, a.x * a.z * k + a.y * s},
             Vec3{a.y * a.x * k + a.z * s, c + a.y * a.y * k, a.y * a.z * k - a.x * s},
             Vec3{a.z * a.x * k - a.y * s, a.z * a.y * k + a.x * s, c + a.z * a.z * k}}};
}

Affine operator*(const Affine& a, const Affine& b) { return {a.m * b.m, a.m * b.t + a.t}; }

std::optional<Affine> inverse(const Affine& a) {
    const auto mi = inverse(a.m);
    if (!mi) return std::nullopt;
    return Affine{*mi, -(*mi * a.t)};
}

static bool is_identity_affine(const Affine& a) {
    const Mat3 id;
    return a.m.r[0] == id.r[0] && a.m.r[1] == id.r[1] && a.m.r[2] == id.r[2] &&
           a.t == Vec3{0, 0, 0};
}

Transform::Transform(const Affine& f, const Affine& i)
    : fwd_(f), inv_(i), identity_(is_identity_affine(f)) {}

std::optional<Transform> Transform::from_affine(const Affine& a) {
    for (const Vec3& row : a.m.r)
        if (!is_finite(row)) return std::nullopt;
    if (!is_finite(a.t)) return std::nullopt;
    const auto inv = lat::inverse(a);
    if (!inv) return std::nullopt;
    return Transform(a, *inv);
}

Transform Transform::translate(Vec3 d) { return Transform({Mat3{}, d}, {Mat3{}, -d}); }

Transform Transform::scale(Vec3 s) {
    return Transform({Mat3::diagonal(s), {}}, {Mat3::diagonal({1 / s.x, 1 / s.y, 1 / s.z}), {}});
}

Transform Transform::rotate(Vec3 axis, double angle) {
    const Mat3 r = rotation(axis, angle);
    return Transform({r, {}}, {transpose(r), {}});
}

Transform operator*(const Transform& a, const Transform& b) {
    return Transform(a.fwd_ * b.fwd_, b.inv_ * a.inv_);
}

// The stretch squared, the largest eigenvalue of M^T M, is at most the largest absolute row sum
// of M^T M (Gershgorin).
double Transform::max_stretch() const {
    if (identity_) return 1.0;
    const Mat3& m = fwd_.m;
    double stretch2 = 0;
    for (int i = 0; i < 3; ++i) {
        double row = 0;
        for (int j = 0; j < 3; ++j) row += std::abs(dot(m.col(i), m.col(j)));
        stretch2 = std::max(stretch2, row);
    }
    return std::sqrt(stretch2) * (1 + 1e-12);
}

Bounds3 Transform::bounds(const Bounds3& b) const {
    if (b.empty() || identity_) return b;
    // Arvo's method: per output axis, sum the extreme contributions of each input axis. Zero
    // entries are skipped so that half-infinite boxes (axis-aligned half-spaces) stay bounded
    // where they can.
    Bounds3 out{fwd_.t, fwd_.t};
    for (std::size_t i = 0; i < 3; ++i) {
        for (std::size_t j = 0; j < 3; ++j) {
            if (fwd_.m.r[i][j] == 0.0) continue;
            const double e = fwd_.m.r[i][j] * b.lo[j];
            const double f = fwd_.m.r[i][j] * b.hi[j];
            out.lo[i] += std::min(e, f);
            out.hi[i] += std::max(e, f);
        }
    }
    return out;
}

}  // namespace lat
