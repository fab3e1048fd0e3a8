#pragma once
// Affine transforms. A Transform keeps both the map and its inverse (as pbrt does), so that
// points, directions and normals move either way without a runtime inversion.
#include <array>
#include <optional>

#include "math/bounds.h"
#include "math/ray.h"
#include "math/vec.h"

namespace lat {

struct Mat3 {
    std::array<Vec3, 3> r{Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};  // rows

    static Mat3 identity() { return {}; }
    static Mat3 diagonal(Vec3 s) { return {{Vec3{s.x, 0, 0}, Vec3{0, s.y, 0}, Vec3{0, 0, s.z}}}; }
    Vec3 col(int j) const {
        const auto k = static_cast<std::size_t>(j);
        return {r[0][k], r[1][k], r[2][k]};
    }
};

inline Vec3 operator*(const Mat3& m, Vec3 v) { return {dot(m.r[0], v), dot(m.r[1], v), dot(m.r[2], v)}; }
Mat3 operator*(const Mat3& a, const Mat3& b);
Mat3 transpose(const Mat3& m);
double determinant(const Mat3& m);
// Inverse, or nothing when the matrix is singular relative to its own scale.
std::optional<Mat3> inverse(const Mat3& m);
// Rotation by angle (radians) about a unit axis (right-handed).
Mat3 rotation(Vec3 axis, double angle);

// x -> m x + t
struct Affine {
    Mat3 m;
    Vec3 t;

    Vec3 point(Vec3 p) const { return m * p + t; }
    Vec3 vector(Vec3 v) const { return m * v; }
};

Affine operator*(const Affine& a, const Affine& b);  // apply b, then a
std::optional<Affine> inverse(const Affine& a);

class Transform {
public:
    Transform() = default;
    // Fails (returns nothing) when the map is singular.
    static std::optional<Transform> from_affine(const Affine& a);
    static Transform translate(Vec3 d);
    static Transform scale(Vec3 s);  // every component non-zero
    static Transform rotate(Vec3 axis, double angle);

    const Affine& forward() const { return fwd_; }
    const Affine& inverse_map() const { return inv_; }
    Transform inverse() const { return Transform(inv_, fwd_); }
    bool is_identity() const { return identity_; }

    Vec3 point(Vec3 p) const { return fwd_.point(p); }
    Vec3 vector(Vec3 v) const { return fwd_.vector(v); }
    // Normals go by the inverse transpose; the result is not normalised.
    Vec3 normal(Vec3 n) const { return transpose(inv_.m) * n; }
    Ray ray(const Ray& r) const { return {fwd_.point(r.o), fwd_.vector(r.d)}; }
    Bounds3 bounds(const Bounds3& b) const;
    // An upper bound on how much the map stretches a length (|M v| <= max_stretch() |v|):
    // exact for rotations and scales, safe for shears.
    double max_stretch() const;

    Vec3 inverse_point(Vec3 p) const { return inv_.point(p); }
    Vec3 inverse_vector(Vec3 v) const { return inv_.vector(v); }
    Ray inverse_ray(const Ray& r) const { return {inv_.point(r.o), inv_.vector(r.d)}; }

    friend Transform operator*(const Transform& a, const Transform& b);  // apply b, then a

private:
    Transform(const Affine& f, const Affine& i);
    Affine fwd_{};
    Affine inv_{};
    bool identity_ = true;
};

}  // namespace lat
