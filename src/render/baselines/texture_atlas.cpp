#include "render/baselines/texture_atlas.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <vector>

#include "geometry/sphere.h"
#include "geometry/triangle_mesh.h"

namespace lat {
namespace {

const SphereShape* sphere_of(const SceneObject& o) {
    return o.primitive < 0 ? as_sphere(*o.shape) : nullptr;
}
const TriangleMeshShape* mesh_of(const SceneObject& o) {
    return o.primitive < 0 ? as_mesh(*o.shape) : nullptr;
}

class SphereAtlas final : public TextureAtlas {
public:
    SphereAtlas(const SphereShape& s, int width)
        : s_(s), w_(std::max(2, width)), h_(std::max(1, w_ / 2)) {}

    std::size_t texel_count() const override { return static_cast<std::size_t>(w_) * h_; }
    std::uint64_t layout_bytes() const override { return 0; }
    bool texel_point(std::size_t t, double a, double b, SurfacePoint& out) const override {
        const auto i = static_cast<int>(t % w_), j = static_cast<int>(t / w_);
        out.n = uv_to_direction((i + a) / w_, (j + b) / h_);
        out.p = s_.center() + out.n * s_.radius();
        return true;
    }
    double texel_area(std::size_t t) const override {
        const auto j = static_cast<double>(t / w_);
        const double band = std::cos(M_PI * j / h_) - std::cos(M_PI * (j + 1) / h_);
        return s_.radius() * s_.radius() * (2 * M_PI / w_) * band;
    }
    TexelWeights lookup(Vec3 p, std::uint32_t) const override {
        double u, v;
        direction_to_uv(normalize(p - s_.center()), u, v);
        const double x = u * w_ - 0.5, y = std::clamp(v * h_ - 0.5, 0.0, h_ - 1.0);
        const int i0 = static_cast<int>(std::floor(x)), j0 = static_cast<int>(std::floor(y));
        const double fx = x - i0, fy = y - j0;
        TexelWeights tw;
        for (int dj = 0; dj <= 1; ++dj)
            for (int di = 0; di <= 1; ++di) {
                const int i = ((i0 + di) % w_ + w_) % w_, j = std::min(h_ - 1, j0 + dj);
                tw.texel[static_cast<std::size_t>(tw.count)] = static_cast<std::size_t>(j) * w_ + i;
                tw.weight[static_cast<std::size_t>(tw.count++)] =
                    (di ? fx : 1 - fx) * (dj ? fy : 1 - fy);
            }
        return tw;
    }

private:
    const SphereShape& s_;
    int w_, h_;
};

// Triangle k's grid has n_[k] cells a side, of which the n (n + 1) / 2 with i + j < n are
// stored from first_[k] on, row j (n - j cells) after rows 0..j-1.
class MeshAtlas final : public TextureAtlas {
public:
    MeshAtlas(const TriangleMeshShape& m, const Transform& xf, int width) : m_(m) {
        const auto& tris = m.triangles();
        std::vector<double> world_area(tris.size());
        double total = 0;
        for (std::size_t k = 0; k < tris.size(); ++k) {
            const Vec3 a = xf.point(vertex(k, 0)), b = xf.point(vertex(k, 1)),
                       c = xf.point(vertex(k, 2));
            world_area[k] = 0.5 * length(cross(b - a, c - a));
            total += world_area[k];
        }
        // Texels of about equal world area h^2, width^2 / 2 of them over the whole mesh.
        const double budget = 0.5 * static_cast<double>(width) * width;
        const double texel_area = total > 0 ? total / budget : 1;
        n_.resize(tris.size());
        first_.resize(tris.size() + 1, 0);
        for (std::size_t k = 0; k < tris.size(); ++k) {
            const double n = std::round(std::sqrt(2 * world_area[k] / texel_area));
            n_[k] = static_cast<std::uint32_t>(std::clamp(n, 1.0, 65535.0));
            first_[k + 1] = first_[k] + std::size_t{n_[k]} * (n_[k] + 1) / 2;
        }
    }

    std::size_t texel_count() const override { return first_.back(); }
    std::uint64_t layout_bytes() const override {
        return n_.size() * (sizeof(std::uint32_t) + sizeof(std::size_t));
    }
    bool texel_point(std::size_t t, double a, double b, SurfacePoint& out) const override {
        std::size_t k, i, j;
        locate(t, k, i, j);
        const double n = n_[k], u = (i + a) / n, v = (j + b) / n;
        if (u + v > 1) return false;
        out.p = (1 - u - v) * vertex(k, 0) + u * vertex(k, 1) + v * vertex(k, 2);
        out.n = m_.shading_normal(k, u, v);
        return true;
    }
    double texel_area(std::size_t t) const override {
        std::size_t k, i, j;
        locate(t, k, i, j);
        const double parallelogram =
            length(cross(vertex(k, 1) - vertex(k, 0), vertex(k, 2) - vertex(k, 0)));
        const double cell = parallelogram / (double(n_[k]) * n_[k]);
        return i + j + 1 == n_[k] ? cell / 2 : cell;
    }
    TexelWeights lookup(Vec3 p, std::uint32_t part) const override {
        assert(part < n_.size());
        const std::size_t k = part;
        // Barycentrics of p (on the triangle, up to rounding).
        const Vec3 a = vertex(k, 0), e0 = vertex(k, 1) - a, e1 = vertex(k, 2) - a, w = p - a;
        const double d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1);
        const double d20 = dot(w, e0), d21 = dot(w, e1), den = d00 * d11 - d01 * d01;
        const double u = den > 0 ? (d11 * d20 - d01 * d21) / den : 0;
        const double v = den > 0 ? (d00 * d21 - d01 * d20) / den : 0;
        const int n = static_cast<int>(n_[k]);
        const double x = u * n - 0.5, y = v * n - 0.5;
        const int i0 = static_cast<int>(std::floor(x)), j0 = static_cast<int>(std::floor(y));
        const double fx = x - i0, fy = y - j0;
        TexelWeights tw;
        double sum = 0;
        for (int dj = 0; dj <= 1; ++dj)
            for (int di = 0; di <= 1; ++di) {
                const int i = std::clamp(i0 + di, 0, n - 1), j = std::clamp(j0 + dj, 0, n - 1);
                const double wgt = (di ? fx : 1 - fx) * (dj ? fy : 1 - fy);
                if (i + j >= n || !(wgt > 0)) continue;  // off the triangle
                tw.texel[static_cast<std::size_t>(tw.count)] = index(k, i, j);
                tw.weight[static_cast<std::size_t>(tw.count++)] = wgt;
                sum += wgt;
            }
        if (tw.count == 0) {  // beyond the diagonal by rounding: the nearest diagonal texel
            const int j = std::clamp(static_cast<int>(std::floor(v * n)), 0, n - 1);
            tw.texel[0] = index(k, n - 1 - j, j);
            tw.weight[0] = sum = 1;
            tw.count = 1;
        }
        for (int c = 0; c < tw.count; ++c) tw.weight[static_cast<std::size_t>(c)] /= sum;
        return tw;
    }

private:
    const TriangleMeshShape& m_;
    std::vector<std::uint32_t> n_;
    std::vector<std::size_t> first_;

    Vec3 vertex(std::size_t k, std::size_t c) const { return m_.positions()[m_.triangles()[k][c]]; }
    std::size_t index(std::size_t k, int i, int j) const {
        const std::size_t n = n_[k], jj = static_cast<std::size_t>(j);
        return first_[k] + jj * (2 * n - jj + 1) / 2 +
               static_cast<std::size_t>(i);  // after rows 0..j-1
    }
    void locate(std::size_t t, std::size_t& k, std::size_t& i, std::size_t& j) const {
        k = static_cast<std::size_t>(std::upper_bound(first_.begin(), first_.end(), t) -
                                     first_.begin()) -
            1;
        std::size_t r = t - first_[k], n = n_[k];
        for (j = 0; r >= n - j; ++j) r -= n - j;
        i = r;
    }
};

}  // namespace

void direction_to_uv(Vec3 d, double& u, double& v) {
    u = std::atan2(d.y, d.x) / (2 * M_PI) + 0.5;
    v = std::acos(std::clamp(d.z, -1.0, 1.0)) / M_PI;
}

Vec3 uv_to_direction(double u, double v) {
    const double phi = (u - 0.5) * 2 * M_PI, theta = v * M_PI;
    return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

bool has_texture_atlas(const SceneObject& base) {
    return sphere_of(base) || mesh_of(base);
}

std::unique_ptr<TextureAtlas> make_texture_atlas(const SceneObject& base, int width) {
    if (const SphereShape* s = sphere_of(base)) return std::make_unique<SphereAtlas>(*s, width);
    const TriangleMeshShape* m = mesh_of(base);
    assert(m);
    return std::make_unique<MeshAtlas>(*m, base.xf, width);
}

}  // namespace lat
