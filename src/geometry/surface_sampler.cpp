#include "geometry/surface_sampler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "util/error.h"

namespace lat {
namespace {

// A point of a canonical surface: position, unit outward normal, and the area element
// |dp/du x dp/dv| of the parametrisation.
struct ParamPoint {
    Vec3 p, n;
    double jac;
};

ParamPoint eval(ParamKind kind, double minor, double u, double v) {
    if (kind == ParamKind::kPlane) return {{u, v, 0}, {0, 0, 1}, 1};
    // Every other surface goes around an axis: u is the angle (the plane, above, spares the
    // area's integration a million sines on a ground patch).
    const double cu = std::cos(u), su = std::sin(u);
    switch (kind) {
        case ParamKind::kSphere: {  // (u, z): Archimedes' equal-area map, jac = 1
            const double r = std::sqrt(std::max(0.0, 1 - v * v));
            const Vec3 p{r * cu, r * su, v};
            return {p, p, 1};
        }
        case ParamKind::kCylinder:
            return {{cu, su, v}, {cu, su, 0}, 1};
        case ParamKind::kCone: {  // (u, z)
            const double s = v < 0 ? -1 : 1;
            return {{v * cu, v * su, v}, normalize(Vec3{cu, su, -1} * s), std::abs(v) * M_SQRT2};
        }
        case ParamKind::kParaboloid: {  // (u, rho)
            const Vec3 g{2 * v * cu, 2 * v * su, -1};
            return {{v * cu, v * su, v * v}, normalize(g), v * std::sqrt(1 + 4 * v * v)};
        }
        case ParamKind::kHyperboloid1: {  // (u, s): z = sinh s
            const double ch = std::cosh(v), sh = std::sinh(v);
            const Vec3 p{ch * cu, ch * su, sh};
            return {p, normalize(Vec3{p.x, p.y, -p.z}), ch * std::sqrt(ch * ch + sh * sh)};
        }
        case ParamKind::kHyperboloid2: {  // (u, v): the sheet z = sign(v) cosh v
            const double s = std::abs(v), ch = std::cosh(s), sh = std::sinh(s);
            const Vec3 p{sh * cu, sh * su, v < 0 ? -ch : ch};
            return {p, normalize(Vec3{p.x, p.y, -p.z}), sh * std::sqrt(ch * ch + sh * sh)};
        }
        case ParamKind::kTorus: {  // (u, v): v around the tube
            const double cv = std::cos(v), sv = std::sin(v), ring = 1 + minor * cv;
            return {{ring * cu, ring * su, minor * sv}, {cv * cu, cv * su, sv}, minor * ring};
        }
        case ParamKind::kPlane:
            break;
    }
    return {};
}

struct Domain {
    double u0, u1, v0, v1;
};

// The parameter rectangle covering the part of the surface inside the canonical box `cb`.
Domain domain(ParamKind kind, const Bounds3& cb) {
    const double tau = 2 * M_PI;
    const double z0 = cb.lo.z, z1 = cb.hi.z;
    switch (kind) {
        case ParamKind::kSphere: return {0, tau, std::max(-1.0, z0), std::min(1.0, z1)};
        case ParamKind::kCylinder:
        case ParamKind::kCone: return {0, tau, z0, z1};
        case ParamKind::kParaboloid: return {0, tau, 0, std::sqrt(std::max(0.0, z1))};
        case ParamKind::kHyperboloid1: return {0, tau, std::asinh(z0), std::asinh(z1)};
        case ParamKind::kHyperboloid2:
            return {0, tau, z0 <= -1 ? -std::acosh(-z0) : 0.0, z1 >= 1 ? std::acosh(z1) : 0.0};
        case ParamKind::kTorus: return {0, tau, 0, tau};
        case ParamKind::kPlane: return {cb.lo.x, cb.hi.x, cb.lo.y, cb.hi.y};
    }
    return {};
}

class ParamSampler final : public SurfaceSampler {
public:
    ParamSampler(ParamKind kind, double minor, const Transform& xf, const std::optional<Bounds3>& box)
        : kind_(kind), minor_(minor), xf_(xf), box_(box) {
        const double det = determinant(xf.forward().m);
        det_ = std::abs(det);
        Bounds3 cb = Bounds3::infinite();
        if (box) {
            cb = Bounds3{};
            for (int i = 0; i < 8; ++i) cb = merge(cb, xf.inverse_point(box->corner(i)));
        }
        dom_ = domain(kind, cb);
        integrate();
        // Samples lie in the box when there is one (sample() keeps no other), else on the
        // bounded surfaces (sphere, torus) inside their canonical box, placed.
        if (box) {
            bounds_ = *box;
        } else if (param_kind_unbounded(kind)) {
            bounds_ = Bounds3::infinite();
        } else {
            const bool torus = kind == ParamKind::kTorus;
            const double r = torus ? 1 + minor : 1, h = torus ? minor : 1;
            const Bounds3 canonical{{-r, -r, -h}, {r, r, h}};
            for (int i = 0; i < 8; ++i) bounds_ = merge(bounds_, xf.point(canonical.corner(i)));
        }
    }

    double area() const override { return area_; }
    Bounds3 bounds() const override { return bounds_; }

    // Uniform in the parameter rectangle, kept with probability (world area element) / (its
    // largest value): area-uniform on the surface.
    SurfaceSample sample(CounterRng& rng) const override {
        // The acceptance rate is at least kMinAcceptance (checked when built), so this many
        // tries fail with probability below e^-1000.
        const long tries = static_cast<long>(1000 / kMinAcceptance);
        for (long k = 0; k < tries; ++k) {
            const double u = rng.uniform(dom_.u0, dom_.u1), v = rng.uniform(dom_.v0, dom_.v1);
            const double keep = rng.uniform() * jac_max_;
            SurfaceSample s;
            const double j = world(u, v, s);
            if (j > keep && (!box_ || contains(*box_, s.p))) return s;
        }
        throw std::logic_error("surface sampler: rejection sampling did not finish");
    }

private:
    static constexpr double kMinAcceptance = 1e-3;
    static constexpr int kGrid = 1024;  // midpoint rule for the area: error well below 0.1 %
    ParamKind kind_;
    double minor_;
    Transform xf_;
    std::optional<Bounds3> box_;
    double det_ = 1;
    Domain dom_{};
    double area_ = 0, jac_max_ = 0;
    Bounds3 bounds_;

    // The world point and unit normal at (u, v), and the world area element there: a surface
    // element of unit normal n and area dA becomes |det M| |M^-T n| dA under the linear part M.
    double world(double u, double v, SurfaceSample& s) const {
        const ParamPoint q = eval(kind_, minor_, u, v);
        const Vec3 nw = xf_.normal(q.n);
        const double len = length(nw);
        s.p = xf_.point(q.p);
        s.n = nw / len;
        return q.jac * det_ * len;
    }

    void integrate() {
        const double du = (dom_.u1 - dom_.u0) / kGrid, dv = (dom_.v1 - dom_.v0) / kGrid;
        if (!(du > 0) || !(dv > 0)) throw InputError("the box holds none of the surface");
        double sum = 0;
        for (int i = 0; i < kGrid; ++i)
            for (int j = 0; j < kGrid; ++j) {
                SurfaceSample s;
                const double jac = world(dom_.u0 + (i + 0.5) * du, dom_.v0 + (j + 0.5) * dv, s);
                jac_max_ = std::max(jac_max_, jac);
                if (!box_ || contains(*box_, s.p)) sum += jac;
            }
        // The grid's midpoints miss the peak between them by O(du²): 2 % headroom covers it for
        // any surface we parametrise (the area element varies smoothly).
        jac_max_ *= 1.02;
        area_ = sum * du * dv;
        if (!std::isfinite(area_))
            throw InputError("the surface's area, placed, is not a finite number (its size or "
                             "placement is too extreme)");
        if (!(area_ > 0))
            throw InputError(box_ ? "the box holds none of the surface"
                                  : "the surface has no area to scatter on");
        const double acceptance = area_ / (jac_max_ * (dom_.u1 - dom_.u0) * (dom_.v1 - dom_.v0));
        if (acceptance < kMinAcceptance)
            throw InputError("the box holds too small a part of the surface to sample (" +
                             std::to_string(acceptance * 100) + " % of the region searched)");
    }
};

class MeshSampler final : public SurfaceSampler {
public:
    MeshSampler(std::shared_ptr<const TriangleMeshShape> mesh, const Transform& xf)
        : mesh_(std::move(mesh)), xf_(xf) {
        const auto& pos = mesh_->positions();
        const auto& tris = mesh_->triangles();
        cdf_.reserve(tris.size());
        double sum = 0;
        for (const auto& t : tris) {
            const Vec3 a = xf.point(pos[t[0]]), b = xf.point(pos[t[1]]), c = xf.point(pos[t[2]]);
            sum += 0.5 * length(cross(b - a, c - a));
            cdf_.push_back(sum);
            bounds_ = merge(merge(merge(bounds_, a), b), c);
        }
        if (!std::isfinite(sum))
            throw InputError("the mesh's area, placed, is not a finite number (its size or "
                             "placement is too extreme)");
        if (!(sum > 0)) throw InputError("the mesh has no area to scatter on");
    }

    double area() const override { return cdf_.back(); }
    Bounds3 bounds() const override { return bounds_; }

    SurfaceSample sample(CounterRng& rng) const override {
        const double x = rng.uniform() * cdf_.back();
        std::size_t tri = static_cast<std::size_t>(std::upper_bound(cdf_.begin(), cdf_.end(), x) - cdf_.begin());
        tri = std::min(tri, cdf_.size() - 1);
        while (tri > 0 && cdf_[tri] == cdf_[tri - 1]) --tri;  // never a zero-area triangle
        // Uniform in the triangle: (1 - sqrt r1) a + sqrt r1 (1 - r2) b + sqrt r1 r2 c.
        const double s = std::sqrt(rng.uniform()), r2 = rng.uniform();
        const double u = s * (1 - r2), v = s * r2;
        const auto& t = mesh_->triangles()[tri];
        const auto& pos = mesh_->positions();
        const Vec3 p = (1 - u - v) * pos[t[0]] + u * pos[t[1]] + v * pos[t[2]];
        return {xf_.point(p), normalize(xf_.normal(mesh_->shading_normal(tri, u, v)))};
    }

private:
    std::shared_ptr<const TriangleMeshShape> mesh_;
    Transform xf_;
    std::vector<double> cdf_;  // running sum of world triangle areas
    Bounds3 bounds_;           // of the triangles' corners, placed
};

}  // namespace

bool param_kind_unbounded(ParamKind k) {
    return k != ParamKind::kSphere && k != ParamKind::kTorus;
}

std::unique_ptr<SurfaceSampler> make_param_sampler(ParamKind kind, double minor,
                                                   const Transform& xf,
                                                   const std::optional<Bounds3>& box) {
    return std::make_unique<ParamSampler>(kind, minor, xf, box);
}

std::unique_ptr<SurfaceSampler> make_mesh_sampler(std::shared_ptr<const TriangleMeshShape> mesh,
                                                  const Transform& xf) {
    return std::make_unique<MeshSampler>(std::move(mesh), xf);
}

}  // namespace lat
