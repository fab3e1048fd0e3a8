#include "lattice/rasterizer.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "lattice/boundary_grid.h"
#include "lattice/octahedral.h"
#include "util/progress.h"

namespace lat {
namespace {

constexpr std::uint32_t kBlock = 32;  // entry points per task

struct FaceLayout {
    int axis, level, ua, va, nu, nv;  // nu, nv: points along u and v
    std::vector<std::uint8_t> mask;    // faces of each point
    std::vector<std::uint8_t> canonical;  // 1 where this face is the point's lowest face
    std::vector<std::uint32_t> ids;
};

struct Scratch {
    std::vector<double> best_t;
    std::vector<Crossing> best_c;
    std::vector<std::uint32_t> tested;  // generation of the last part tested at each point
    std::uint32_t generation = 0;
    std::vector<std::size_t> touched;   // face points with a hit, to emit and reset
};

// The face-grid rectangle that can hold exits of segments from p that meet the box b: the
// central projection of b's corners from p onto the face plane; the whole face when the
// projection is unbounded (a corner level with p or behind it).
void projected_range(const Vec3& p, const Bounds3& b, const FaceLayout& f, int& u0, int& u1,
                     int& v0, int& v1) {
    u0 = 0, u1 = f.nu - 1, v0 = 0, v1 = f.nv - 1;
    const auto ax = static_cast<std::size_t>(f.axis), ua = static_cast<std::size_t>(f.ua),
               va = static_cast<std::size_t>(f.va);
    const double num = f.level - p[ax];
    if (num == 0) return;
    double umin = kInfinity, umax = -kInfinity, vmin = kInfinity, vmax = -kInfinity;
    for (int k = 0; k < 8; ++k) {
        const Vec3 c = b.corner(k);
        const double den = c[ax] - p[ax];
        if (den * num <= 0) return;
        const double s = num / den;
        const double u = p[ua] + s * (c[ua] - p[ua]), v = p[va] + s * (c[va] - p[va]);
        umin = std::min(umin, u), umax = std::max(umax, u);
        vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    }
    const double eps = 1e-9;
    u0 = static_cast<int>(std::ceil(std::max(umin - eps, double(u0))));
    u1 = static_cast<int>(std::floor(std::min(umax + eps, double(u1))));
    v0 = static_cast<int>(std::ceil(std::max(vmin - eps, double(v0))));
    v1 = static_cast<int>(std::floor(std::min(vmax + eps, double(v1))));
}

struct PartSphere {
    Vec3 c;  // lattice units
    double r;
    std::uint32_t part;
};

// Row v of face f: the u-interval of exits q whose segment from p can meet the sphere (c, r),
// i.e. q inside the cone from p around the sphere. Conservative (padded against rounding);
// returns false for an empty interval.
bool cone_row(const Vec3& p, const PartSphere& s, const FaceLayout& f, int v, double& ulo,
              double& uhi) {
    const auto ax = static_cast<std::size_t>(f.axis), ua = static_cast<std::size_t>(f.ua),
               va = static_cast<std::size_t>(f.va);
    const Vec3 w = s.c - p;
    const double k = length_squared(w) - s.r * s.r;  // |w|^2 cos^2(half angle) * ...
    const double da = f.level - p[ax], dv = v - p[va];
    const double alpha = da * w[ax] + dv * w[va], beta = w[ua];
    const double gamma = da * da + dv * dv;
    // g(u') = (alpha + beta u')^2 - k (gamma + u'^2) >= 0 with alpha + beta u' >= 0, u' = u - p_u.
    const double A = beta * beta - k, B = alpha * beta, C = alpha * alpha - k * gamma;
    if (k <= 0 || A >= 0) {  // p inside the sphere, or the cone opens along u: the whole row
        ulo = -kInfinity, uhi = kInfinity;
        return true;
    }
    const double disc = B * B - A * C;
    if (disc < 0) return false;
    const double sq = std::sqrt(disc);
    const double r0 = (-B + sq) / A, r1 = (-B - sq) / A;  // r0 <= r1 since A < 0
    if (alpha + beta * 0.5 * (r0 + r1) < 0) return false;  // the cone's far nappe
    const double pad = 1e-7 * (1 + std::abs(r0) + std::abs(r1));
    ulo = p[ua] + r0 - pad;
    uhi = p[ua] + r1 + pad;
    return true;
}

}  // namespace

RasterizeResult rasterize(const Shape& shape, const LatticeGrid& lg, const RasterizeOptions& opt) {
    const auto start = std::chrono::steady_clock::now();
    const BoundaryGrid grid(lg.cells);
    const double h = lg.cell;

    // Per face: its grid, which face each point belongs to, and the point ids.
    std::array<FaceLayout, 6> faces;
    for (int f = 0; f < 6; ++f) {
        FaceLayout& fl = faces[static_cast<std::size_t>(f)];
        fl.axis = BoundaryGrid::face_axis(f);
        fl.level = grid.face_level(f);
        fl.ua = (fl.axis + 1) % 3;
        fl.va = (fl.axis + 2) % 3;
        fl.nu = lg.cells[static_cast<std::size_t>(fl.ua)] + 1;
        fl.nv = lg.cells[static_cast<std::size_t>(fl.va)] + 1;
        const std::size_t n = static_cast<std::size_t>(fl.nu) * static_cast<std::size_t>(fl.nv);
        fl.mask.resize(n), fl.canonical.resize(n), fl.ids.resize(n);
        for (int v = 0; v < fl.nv; ++v)
            for (int u = 0; u < fl.nu; ++u) {
                GridPoint q;
                q[fl.axis] = fl.level, q[fl.ua] = u, q[fl.va] = v;
                const std::size_t k = static_cast<std::size_t>(v) * static_cast<std::size_t>(fl.nu) + static_cast<std::size_t>(u);
                fl.mask[k] = grid.faces(q);
                fl.canonical[k] = (__builtin_ctz(fl.mask[k]) == f) ? 1 : 0;
                fl.ids[k] = grid.id(q);
            }
    }

    // The primitive's parts as bounding spheres in lattice units, grouped by part.
    std::vector<PartSphere> spheres;
    for (std::size_t i = 0; i < shape.primitive_count(); ++i) {
        std::vector<BoundingSphere> bs;
        shape.primitive_spheres(i, bs);
        for (const BoundingSphere& b : bs)
            // Padded beyond the parts' touch tolerance, so culling never drops a touching hit.
            spheres.push_back({b.center / h, b.radius / h * (1 + 1e-6) + 1e-9,
                               static_cast<std::uint32_t>(i)});
    }

    const std::uint32_t npoints = grid.count();
    const std::uint32_t nblocks = (npoints + kBlock - 1) / kBlock;
    std::vector<std::vector<RawHit>> block_hits(opt.keep_hits ? nblocks : 0);
    struct Counts {
        std::uint64_t enumerated = 0, traced = 0, hits = 0, counted = 0, tests = 0;
    };
    std::vector<Counts> block_counts(nblocks);
    tbb::enumerable_thread_specific<Scratch> scratch;
    ProgressBar bar("rasterize", npoints, opt.progress);

    tbb::parallel_for(std::uint32_t{0}, nblocks, [&](std::uint32_t blk) {
        Scratch& s = scratch.local();
        Counts cnt;
        std::vector<RawHit> out;
        const std::uint32_t a_end = std::min(npoints, (blk + 1) * kBlock);
        for (std::uint32_t a = blk * kBlock; a < a_end; ++a) {
            if (a % opt.entry_stride != 0) continue;
            const GridPoint gp = grid.point(a);
            const std::uint8_t fa = grid.faces(gp);
            const Vec3 p{double(gp.x), double(gp.y), double(gp.z)};
            // Eq. (2) also counts a point paired with itself on two of its faces.
            const int nf = __builtin_popcount(fa);
            cnt.enumerated += static_cast<std::uint64_t>(nf * nf - nf);
            const bool start_inside = shape.inside(p * h);
            for (int f = 0; f < 6; ++f) {
                const FaceLayout& fl = faces[static_cast<std::size_t>(f)];
                const std::size_t n = fl.mask.size();
                if (s.best_t.size() < n) {
                    s.best_t.assign(n, kInfinity);
                    s.best_c.resize(n);
                    s.tested.assign(n, 0);
                }
                std::uint32_t last_part = ~0u;
                for (const PartSphere& ps : spheres) {
                    if (start_inside) break;
                    if (ps.part != last_part) {
                        last_part = ps.part;
                        ++s.generation;  // marks "tested for this part" in s.tested
                    }
                    int u0, u1, v0, v1;
                    const Bounds3 sb{ps.c - Vec3{ps.r, ps.r, ps.r}, ps.c + Vec3{ps.r, ps.r, ps.r}};
                    projected_range(p, sb, fl, u0, u1, v0, v1);
                    for (int v = v0; v <= v1; ++v) {
                        double ulo, uhi;
                        if (!cone_row(p, ps, fl, v, ulo, uhi)) continue;
                        // Clamp in double first: the interval may be unbounded or huge.
                        const int ub = static_cast<int>(std::ceil(std::max(ulo, double(u0))));
                        const int ue = static_cast<int>(std::floor(std::min(uhi, double(u1))));
                        for (int u = ub; u <= ue; ++u) {
                            const std::size_t k = static_cast<std::size_t>(v) * static_cast<std::size_t>(fl.nu) + static_cast<std::size_t>(u);
                            if (!fl.canonical[k] || s.tested[k] == s.generation) continue;
                            s.tested[k] = s.generation;
                            GridPoint q;
                            q[fl.axis] = fl.level, q[fl.ua] = u, q[fl.va] = v;
                            const Vec3 qv{double(q.x), double(q.y), double(q.z)};
                            const Ray r{p * h, (qv - p) * h};
                            Crossing c;
                            ++cnt.tests;
                            const double tmax = std::min(s.best_t[k], 1.0 + 1e-12);
                            if (shape.intersect_primitive(ps.part, r, 0.0, tmax, c)) {
                                if (s.best_t[k] == kInfinity) s.touched.push_back(k);
                                s.best_t[k] = c.t;
                                s.best_c[k] = c;
                            }
                        }
                    }
                }
                for (std::size_t k = 0; k < n; ++k) {
                    if (!fl.canonical[k] || fl.ids[k] == a) continue;
                    if (!BoundaryGrid::valid_pair(fa, fl.mask[k])) continue;
                    const int m = BoundaryGrid::multiplicity(fa, fl.mask[k]);
                    cnt.enumerated += static_cast<std::uint64_t>(m);
                    ++cnt.traced;
                    const bool hit = start_inside || s.best_t[k] <= 1.0;
                    if (!hit) continue;
                    ++cnt.hits;
                    cnt.counted += static_cast<std::uint64_t>(m);
                    if (!opt.keep_hits) continue;
                    const GridPoint q = grid.point(fl.ids[k]);
                    const Vec3 qv{double(q.x), double(q.y), double(q.z)};
                    const Ray r{p * h, (qv - p) * h};
                    Vec3 nrm;
                    float t;
                    if (start_inside) {
                        t = 0.0f;
                        nrm = normalize(-r.d);
                    } else {
                        t = static_cast<float>(std::min(1.0, s.best_t[k]));
                        nrm = shape.normal(r, s.best_c[k]);
                    }
                    const Oct o = oct_encode(nrm, kRawNormalBits);
                    out.push_back({a, fl.ids[k], t, static_cast<std::uint16_t>(o.u),
                                   static_cast<std::uint16_t>(o.v)});
                }
                for (const std::size_t k : s.touched) s.best_t[k] = kInfinity;
                s.touched.clear();
            }
        }
        if (opt.keep_hits) {
            std::sort(out.begin(), out.end(),
                      [](const RawHit& x, const RawHit& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
            block_hits[blk] = std::move(out);
        }
        block_counts[blk] = cnt;
        bar.add(a_end - blk * kBlock);
    });
    bar.finish();

    RasterizeResult res;
    res.grid = lg;
    res.pairs_eq2 = grid.pairs_eq2();
    for (const Counts& c : block_counts) {
        res.pairs_enumerated += c.enumerated;
        res.pairs_traced += c.traced;
        res.hits += c.hits;
        res.hits_counted += c.counted;
        res.tests += c.tests;
    }
    if (opt.keep_hits) {
        res.raw.reserve(res.hits);
        for (auto& b : block_hits) res.raw.insert(res.raw.end(), b.begin(), b.end());
    }
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return res;
}

}  // namespace lat
