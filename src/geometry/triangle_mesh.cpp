#include "geometry/triangle_mesh.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace lat {

bool intersect_triangle(const Ray& r, Vec3 a, Vec3 b, Vec3 c, double& t, double& u, double& v) {
    constexpr double kEdge = 1e-12;
    const Vec3 e1 = b - a, e2 = c - a;
    const Vec3 p = cross(r.d, e2);
    const double det = dot(e1, p);
    if (det == 0 || !std::isfinite(det)) return false;
    const double inv = 1.0 / det;
    const Vec3 s = r.o - a;
    u = dot(s, p) * inv;
    if (u < -kEdge || u > 1 + kEdge) return false;
    const Vec3 q = cross(s, e1);
    v = dot(r.d, q) * inv;
    if (v < -kEdge || u + v > 1 + kEdge) return false;
    t = dot(e2, q) * inv;
    return std::isfinite(t);
}

TriangleMeshShape::TriangleMeshShape(std::vector<Vec3> positions, std::vector<Triangle> triangles,
                                     std::vector<Vec3> normals, bool smooth)
    : positions_(std::move(positions)), triangles_(std::move(triangles)),
      normals_(std::move(normals)) {
    for (const Triangle& t : triangles_)
        for (const std::uint32_t k : t) bounds_ = merge(bounds_, positions_[k]);
    check_closed();
    compute_normals(smooth);
    bvh_ = MeshBvh(positions_, triangles_);
}

// Closed: every directed edge appears once and its reverse once, with vertices identified by
// position (files with per-face normals repeat a vertex once per normal). Then the signed volume
// says whether the faces wind outwards.
void TriangleMeshShape::check_closed() {
    std::vector<std::uint32_t> order(positions_.size()), weld(positions_.size());
    for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    auto less = [&](std::uint32_t a, std::uint32_t b) {
        const Vec3 p = positions_[a], q = positions_[b];
        return p.x < q.x || (p.x == q.x && (p.y < q.y || (p.y == q.y && p.z < q.z)));
    };
    std::sort(order.begin(), order.end(), less);
    for (std::size_t k = 0; k < order.size(); ++k)
        weld[order[k]] = k > 0 && !less(order[k - 1], order[k]) ? weld[order[k - 1]] : order[k];

    std::unordered_map<std::uint64_t, int> edges;
    edges.reserve(3 * triangles_.size());
    auto key = [](std::uint32_t a, std::uint32_t b) { return (std::uint64_t{a} << 32) | b; };
    for (const Triangle& t : triangles_)
        for (std::size_t e = 0; e < 3; ++e) ++edges[key(weld[t[e]], weld[t[(e + 1) % 3]])];
    closed_ = !triangles_.empty();
    for (const auto& [k, n] : edges) {
        const auto a = static_cast<std::uint32_t>(k >> 32), b = static_cast<std::uint32_t>(k);
        const auto rev = edges.find(key(b, a));
        if (n != 1 || rev == edges.end() || rev->second != 1 || a == b) {
            closed_ = false;
            break;
        }
    }
    if (!closed_) return;
    double volume = 0;
    for (const Triangle& t : triangles_)
        volume += dot(positions_[t[0]], cross(positions_[t[1]], positions_[t[2]]));
    flip_ = volume < 0;
}

// The file's normals made unit (zero stays zero: none). With `smooth`, a vertex without one
// gets the area-weighted average: the unnormalised cross product of each face adds to its
// three corners.
void TriangleMeshShape::compute_normals(bool smooth) {
    if (normals_.size() != positions_.size()) normals_.assign(smooth ? positions_.size() : 0, Vec3{});
    if (smooth) {
        std::vector<bool> given(normals_.size());
        for (std::size_t k = 0; k < normals_.size(); ++k) given[k] = normals_[k] != Vec3{};
        for (const Triangle& t : triangles_) {
            const Vec3 n = cross(positions_[t[1]] - positions_[t[0]], positions_[t[2]] - positions_[t[0]]);
            for (const std::uint32_t k : t)
                if (!given[k]) normals_[k] += flip_ ? -n : n;
        }
    }
    for (Vec3& n : normals_) {
        const double len = length(n);
        n = len > 0 && std::isfinite(len) ? n / len : Vec3{};
    }
    if (std::all_of(normals_.begin(), normals_.end(), [](Vec3 n) { return n == Vec3{}; })) normals_.clear();
}

Vec3 TriangleMeshShape::face_normal(std::size_t tri) const {
    const Triangle& t = triangles_[tri];
    const Vec3 n = cross(positions_[t[1]] - positions_[t[0]], positions_[t[2]] - positions_[t[0]]);
    const double len = length(n);
    if (!(len > 0)) return {0, 0, 1};  // a degenerate triangle is never hit; any answer will do
    return flip_ ? -n / len : n / len;
}

Vec3 TriangleMeshShape::shading_normal(std::size_t tri, double u, double v) const {
    const Triangle& t = triangles_[tri];
    const Vec3 f = face_normal(tri);
    if (normals_.empty()) return f;
    const Vec3 a = normals_[t[0]], b = normals_[t[1]], c = normals_[t[2]];
    if (a == Vec3{} || b == Vec3{} || c == Vec3{}) return f;
    Vec3 n = (1 - u - v) * a + u * b + v * c;
    const double len = length(n);
    if (!(len > 1e-12)) return f;
    n = n / len;
    return dot(n, f) < 0 ? -n : n;  // file normals may wind either way: follow the face
}

bool TriangleMeshShape::intersect_part(std::size_t i, const Ray& r, double tmin, double tmax,
                                            Crossing& hit) const {
    const Triangle& tri = triangles_[i];
    double t, u, v;
    if (!intersect_triangle(r, positions_[tri[0]], positions_[tri[1]], positions_[tri[2]], t, u, v))
        return false;
    if (!(t > tmin && t < tmax)) return false;
    hit = Crossing(t, static_cast<std::uint32_t>(i), 0);
    return true;
}

bool TriangleMeshShape::occluded_part(std::size_t i, const Ray& r, double tmin,
                                           double tmax) const {
    Crossing unused;
    return intersect_part(i, r, tmin, tmax, unused);
}

Bounds3 TriangleMeshShape::part_bounds(std::size_t i) const {
    Bounds3 b;
    for (const std::uint32_t k : triangles_[i]) b = merge(b, positions_[k]);
    return b;
}

Bounds3 TriangleMeshShape::part_bounds(std::size_t i, const Transform& xf) const {
    Bounds3 b;
    for (const std::uint32_t k : triangles_[i]) b = merge(b, xf.point(positions_[k]));
    return b;
}

bool TriangleMeshShape::intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const {
    bool found = false;
    double best = tmax;
    bvh_.traverse(r, tmin, &best, [&](std::uint32_t i) {
        Crossing c;
        if (intersect_part(i, r, tmin, best, c)) {
            hit = c;
            best = c.t;
            found = true;
        }
        return false;
    });
    return found;
}

bool TriangleMeshShape::occluded(const Ray& r, double tmin, double tmax) const {
    bool found = false;
    bvh_.traverse(r, tmin, &tmax, [&](std::uint32_t i) {
        found = occluded_part(i, r, tmin, tmax);
        return found;
    });
    return found;
}

void TriangleMeshShape::part_spans(std::size_t, const Ray& r, SpanList& out) const {
    spans(r, out);
}

void TriangleMeshShape::part_spheres(std::size_t i, std::vector<BoundingSphere>& out) const {
    out.push_back(sphere_around(part_bounds(i)));
}

// Ray parity with orientation: each crossing enters (the ray runs against the outward normal)
// or leaves. A ray through a shared edge or vertex may cross two triangles at one point; such
// twins going the same way count once, while an enter and a leave there (a graze) both count.
void TriangleMeshShape::spans(const Ray& r, SpanList& out) const {
    if (!closed_) return;  // an open mesh bounds no solid (the scene reader keeps it out of CSG)
    struct Hit {
        double t;
        std::uint32_t tri;
        bool enters;
    };
    std::vector<Hit> hits;
    const double inf = kInfinity;
    bvh_.traverse(r, -inf, &inf, [&](std::uint32_t i) {
        const Triangle& tri = triangles_[i];
        double t, u, v;
        if (intersect_triangle(r, positions_[tri[0]], positions_[tri[1]], positions_[tri[2]], t, u, v))
            hits.push_back({t, i, dot(r.d, face_normal(i)) < 0});
        return false;
    });
    std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) {
        return a.t < b.t || (a.t == b.t && a.tri < b.tri);
    });
    const double twin = 1e-9 * (1 + max_component(max(abs(bounds_.lo), abs(bounds_.hi)))) /
                        std::max(length(r.d), 1e-300);
    int depth = 0;
    Crossing in;
    for (std::size_t k = 0; k < hits.size(); ++k) {
        const Hit& h = hits[k];
        if (k > 0 && hits[k - 1].enters == h.enters && h.t - hits[k - 1].t <= twin) continue;
        if (h.enters) {
            if (depth++ == 0) in = Crossing(h.t, h.tri, 0);
        } else if (depth > 0 && --depth == 0 && h.t > in.t) {
            out.push_back({in, Crossing(h.t, h.tri, 0)});
        }
    }
}

Vec3 TriangleMeshShape::normal(const Ray& r, const Crossing& c) const {
    const Triangle& t = triangles_[c.part];
    // Barycentrics of the hit point, from the areas of the sub-triangles it cuts.
    const Vec3 a = positions_[t[0]], b = positions_[t[1]], cc = positions_[t[2]];
    const Vec3 n = cross(b - a, cc - a);
    const double nn = dot(n, n);
    if (!(nn > 0)) return face_normal(c.part);
    const Vec3 p = r.at(c.t);
    const double u = dot(cross(p - a, cc - a), n) / nn;
    const double v = dot(cross(b - a, p - a), n) / nn;
    return shading_normal(c.part, u, v);
}

bool TriangleMeshShape::inside(Vec3 p) const {
    // An irrational-looking direction, so that the test ray rarely meets an edge exactly.
    const Ray r{p, normalize(Vec3{0.5772156649, 0.6180339887, 0.5321159169})};
    SpanList s;
    spans(r, s);
    for (const Span& sp : s)
        if (sp.in.t <= 0 && sp.out.t >= 0) return true;
    return false;
}

const TriangleMeshShape* as_mesh(const Shape& s) {
    return dynamic_cast<const TriangleMeshShape*>(&s);
}

}  // namespace lat
