#include "lattice/encodings/learned/learned_field.h"

#include <bit>
#include <cmath>
#include <stdexcept>

#include "lattice/bits/elias_fano.h"
#include "lattice/octahedral.h"
#include "math/bounds.h"

namespace lat {
namespace {

// Amanatides-Woo traversal of the cells (edge `size`, a power of two) met by the segment in
// [t0, t1], within the cell box [lo, hi): calls visit(cell, ta, tb) in order until it returns
// true. Rounding may skip a sliver of a cell; build and lookups share this code, so whatever it
// does is what the build checked. Written out per axis to keep its state in registers.
template <class Visit>
bool traverse(const FieldSegment& g, double size, double t0, double t1,
              const std::array<int, 3>& lo, const std::array<int, 3>& hi, Visit&& visit) {
    if (!(t0 <= t1)) return false;
    const double inv_size = 1 / size;
    int c[3], st[3];
    double nx[3], dl[3];
    for (std::size_t ax = 0; ax < 3; ++ax) {
        const double f = std::floor((g.o[ax] + g.d[ax] * t0) * inv_size);
        c[ax] = static_cast<int>(std::clamp(f, double(lo[ax]), double(hi[ax] - 1)));
        st[ax] = g.d[ax] > 0 ? 1 : (g.d[ax] < 0 ? -1 : 0);
        nx[ax] =
            st[ax] == 0 ? kInfinity : ((c[ax] + (st[ax] > 0 ? 1 : 0)) * size - g.o[ax]) * g.inv[ax];
        dl[ax] = st[ax] == 0 ? kInfinity : size * std::abs(g.inv[ax]);
    }
    int cx = c[0], cy = c[1], cz = c[2];
    double x = nx[0], y = nx[1], z = nx[2], t = t0;
    for (;;) {
        const double tn = std::min(std::min(x, y), z);
        const double tb = std::max(t, std::min(tn, t1));
        if (visit(std::array<int, 3>{cx, cy, cz}, t, tb)) return true;
        if (!(tn < t1)) return false;
        t = tb;
        if (tn == x) {
            cx += st[0], x += dl[0];
            if (cx < lo[0] || cx >= hi[0]) return false;
        } else if (tn == y) {
            cy += st[1], y += dl[1];
            if (cy < lo[1] || cy >= hi[1]) return false;
        } else {
            cz += st[2], z += dl[2];
            if (cz < lo[2] || cz >= hi[2]) return false;
        }
    }
}

int node_of(int li, int lj, int lk) {
    return (lk * (kBrick + 1) + lj) * (kBrick + 1) + li;
}

}  // namespace

std::uint64_t FieldShape::encode_node(double d, Vec3 n) const {
    const double top = double((std::uint64_t{1} << dist_bits) - 1);
    const auto dc =
        static_cast<std::uint64_t>(std::lround((std::clamp(d / dmax, -1.0, 1.0) + 1) * 0.5 * top));
    const Oct o = oct_encode_precise(n, static_cast<int>(normal_bits));
    return dc | (std::uint64_t{o.u} << dist_bits) |
           (std::uint64_t{o.v} << (dist_bits + normal_bits));
}

FieldView::FieldView(const FieldShape& s, const std::uint64_t* dense_bits,
                     const std::uint64_t* sign_bits, const std::uint64_t* nodes,
                     std::uint64_t dense)
    : s_(s),
      bricks_(s.bricks()),
      dense_(dense_bits),
      sign_(sign_bits),
      nodes_(nodes),
      inv_g_(1 / s.g) {
    const std::uint64_t n = s.brick_count(), words = words_for_bits(n);
    rank_.resize(words);
    std::uint64_t count = 0;
    for (std::uint64_t w = 0; w < words; ++w) {
        rank_[w] = static_cast<std::uint32_t>(count);
        count += static_cast<std::uint64_t>(std::popcount(dense_[w]));
    }
    if (count != dense || ((n & 63) != 0 && (dense_[words - 1] >> (n & 63)) != 0))
        throw std::runtime_error("learned: brick bitmap is inconsistent");
    // Voxels where the field can reach zero, so marching reads only their corners.
    voxels_.assign(dense, 0);
    for (std::uint64_t b = 0; b < dense; ++b) {
        bool le[kBrickNodes];
        for (int i = 0; i < kBrickNodes; ++i)
            le[i] = node_distance(b, i % (kBrick + 1), i / (kBrick + 1) % (kBrick + 1),
                                  i / ((kBrick + 1) * (kBrick + 1))) <= 0;
        for (int v = 0; v < kBrick * kBrick * kBrick; ++v) {
            const int li = v % kBrick, lj = v / kBrick % kBrick, lk = v / (kBrick * kBrick);
            bool any = false;
            for (int c = 0; c < 8; ++c)
                any |= le[node_of(li + (c & 1), lj + ((c >> 1) & 1), lk + (c >> 2))];
            if (any) voxels_[b] |= std::uint64_t{1} << v;
        }
    }
    // Per group of 4^3 bricks, those that are dense or inside: groups with none are skipped
    // whole, and empty bricks without a look at the bitmaps.
    for (std::size_t ax = 0; ax < 3; ++ax) supers_[ax] = (bricks_[ax] + kBrick - 1) / kBrick;
    groups_.assign(
        std::uint64_t(supers_[0]) * std::uint64_t(supers_[1]) * std::uint64_t(supers_[2]), 0);
    for (int k = 0; k < bricks_[2]; ++k)
        for (int j = 0; j < bricks_[1]; ++j)
            for (int i = 0; i < bricks_[0]; ++i)
                if (dense_index(i, j, k) >= 0 || inside_brick(i, j, k))
                    groups_[group_of(i, j, k)] |= std::uint64_t{1} << brick_bit(i, j, k);
}

std::int64_t FieldView::dense_index(int i, int j, int k) const {
    const std::uint64_t bit = (std::uint64_t(k) * std::uint64_t(bricks_[1]) + std::uint64_t(j)) *
                                  std::uint64_t(bricks_[0]) +
                              std::uint64_t(i);
    const std::uint64_t w = dense_[bit >> 6], below = w & ((std::uint64_t{1} << (bit & 63)) - 1);
    if (!((w >> (bit & 63)) & 1)) return -1;
    return static_cast<std::int64_t>(rank_[bit >> 6] +
                                     static_cast<std::uint64_t>(std::popcount(below)));
}

bool FieldView::inside_brick(int i, int j, int k) const {
    const std::uint64_t bit = (std::uint64_t(k) * std::uint64_t(bricks_[1]) + std::uint64_t(j)) *
                                  std::uint64_t(bricks_[0]) +
                              std::uint64_t(i);
    return (sign_[bit >> 6] >> (bit & 63)) & 1;
}

double FieldView::node_distance(std::uint64_t brick, int li, int lj, int lk) const {
    const std::uint64_t pos =
        brick * s_.brick_bits() + std::uint64_t(node_of(li, lj, lk)) * s_.node_bits();
    const double top = double((std::uint64_t{1} << s_.dist_bits) - 1);
    return (double(read_bits(nodes_, pos, s_.dist_bits)) / top * 2 - 1) * s_.dmax;
}

Vec3 FieldView::node_normal(std::uint64_t brick, int li, int lj, int lk) const {
    const std::uint64_t pos = brick * s_.brick_bits() +
                              std::uint64_t(node_of(li, lj, lk)) * s_.node_bits() + s_.dist_bits;
    const std::uint64_t c = read_bits(nodes_, pos, 2 * s_.normal_bits);
    const std::uint64_t mask = (std::uint64_t{1} << s_.normal_bits) - 1;
    // Unit length, so that a voxel's normals weigh as its trilinear weights say (one division
    // instead of normalize's three: this runs eight times a lookup).
    const double scale = 2.0 / double(mask);
    const double px = double(c & mask) * scale - 1, py = double(c >> s_.normal_bits) * scale - 1;
    const double pz = 1 - std::abs(px) - std::abs(py);
    const Vec3 p = pz >= 0 ? Vec3{px, py, pz}
                           : Vec3{(1 - std::abs(py)) * sign_not_zero(px),
                                  (1 - std::abs(px)) * sign_not_zero(py), pz};
    return p * (1 / std::sqrt(dot(p, p)));
}

double FieldView::value_at(Vec3 p, Vec3* n) const {
    std::array<int, 3> v;
    Vec3 f;
    for (std::size_t ax = 0; ax < 3; ++ax) {
        const double c = std::clamp(std::floor(p[ax]), 0.0, double(s_.nodes[ax] - 2));
        v[ax] = static_cast<int>(c);
        f[ax] = std::clamp(p[ax] - c, 0.0, 1.0);
    }
    const int bi = v[0] / kBrick, bj = v[1] / kBrick, bk = v[2] / kBrick;
    if (!((groups_[group_of(bi, bj, bk)] >> brick_bit(bi, bj, bk)) & 1)) {
        if (n) *n = {0, 0, 1};
        return s_.dmax;  // an empty outside brick
    }
    const std::int64_t brick = dense_index(bi, bj, bk);
    if (brick < 0) {
        if (n) *n = {0, 0, 1};
        return inside_brick(v[0] / kBrick, v[1] / kBrick, v[2] / kBrick) ? -s_.dmax : s_.dmax;
    }
    double value = 0;
    Vec3 sum;
    for (int c = 0; c < 8; ++c) {
        const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
        const double w = (dx ? f.x : 1 - f.x) * (dy ? f.y : 1 - f.y) * (dz ? f.z : 1 - f.z);
        const int li = v[0] % kBrick + dx, lj = v[1] % kBrick + dy, lk = v[2] % kBrick + dz;
        value += w * node_distance(std::uint64_t(brick), li, lj, lk);
        if (n) sum += node_normal(std::uint64_t(brick), li, lj, lk) * w;
    }
    if (n) *n = length(sum) > 0 ? normalize(sum) : Vec3{0, 0, 1};
    return value;
}

bool FieldView::voxel_root(std::uint64_t brick, const std::array<int, 3>& v, const FieldSegment& g,
                           double t0, double t1, TableHit& out) const {
    const int li = v[0] % kBrick, lj = v[1] % kBrick, lk = v[2] % kBrick;
    double val[8];
    bool any = false;
    for (int c = 0; c < 8; ++c) {
        val[c] = node_distance(brick, li + (c & 1), lj + ((c >> 1) & 1), lk + (c >> 2));
        any |= val[c] <= 0;
    }
    if (!any) return false;  // trilinear values are convex combinations: no zero here
    const Vec3 corner{double(v[0]), double(v[1]), double(v[2])};
    const Vec3 p0 = g.o + g.d * t0 - corner, dp = g.d * (t1 - t0);
    // The trilinear field as a polynomial in the voxel's coordinates, then along the segment
    // (x = x0 + x1 s, ...) a cubic in s in [0, 1].
    const double a0 = val[0], ax = val[1] - val[0], ay = val[2] - val[0], az = val[4] - val[0];
    const double axy = val[3] - val[2] - val[1] + val[0], axz = val[5] - val[4] - val[1] + val[0];
    const double ayz = val[6] - val[4] - val[2] + val[0];
    const double axyz = val[7] - val[6] - val[5] - val[3] + val[4] + val[2] + val[1] - val[0];
    const double x0 = p0.x, y0 = p0.y, z0 = p0.z, x1 = dp.x, y1 = dp.y, z1 = dp.z;
    const double k3 = axyz * x1 * y1 * z1;
    const double k2 = axy * x1 * y1 + axz * x1 * z1 + ayz * y1 * z1 +
                      axyz * (x0 * y1 * z1 + x1 * y0 * z1 + x1 * y1 * z0);
    const double k1 = ax * x1 + ay * y1 + az * z1 + axy * (x0 * y1 + x1 * y0) +
                      axz * (x0 * z1 + x1 * z0) + ayz * (y0 * z1 + y1 * z0) +
                      axyz * (x1 * y0 * z0 + x0 * y1 * z0 + x0 * y0 * z1);
    const double k0 = a0 + ax * x0 + ay * y0 + az * z0 + axy * x0 * y0 + axz * x0 * z0 +
                      ayz * y0 * z0 + axyz * x0 * y0 * z0;
    auto f = [&](double s) { return ((k3 * s + k2) * s + k1) * s + k0; };
    // Monotone pieces between the cubic's critical points; the first piece ending at or below
    // zero holds the first zero.
    double breaks[4] = {0, 1, 1, 1};
    int nb = 1;
    const double A = 3 * k3, B = 2 * k2, C = k1;
    if (A != 0) {
        const double disc = B * B - 4 * A * C;
        if (disc > 0) {
            const double q = std::sqrt(disc);
            double r0 = (-B - q) / (2 * A), r1 = (-B + q) / (2 * A);
            if (r0 > r1) std::swap(r0, r1);
            if (r0 > 0 && r0 < 1) breaks[nb++] = r0;
            if (r1 > 0 && r1 < 1) breaks[nb++] = r1;
        }
    } else if (B != 0) {
        const double r = -C / B;
        if (r > 0 && r < 1) breaks[nb++] = r;
    }
    breaks[nb++] = 1;
    auto df = [&](double x) { return (A * x + B) * x + C; };
    double s = -1;
    if (f(0) <= 0) s = 0;
    for (int k = 0; k + 1 < nb && s < 0; ++k) {
        double lo = breaks[k], hi = breaks[k + 1];
        const double flo = f(lo), fhi = f(hi);
        if (!(fhi <= 0)) continue;
        // Newton on the monotone piece, kept inside the bracket by bisection.
        double x = flo > fhi ? (flo * hi - fhi * lo) / (flo - fhi) : 0.5 * (lo + hi);
        for (int it = 0; it < 48; ++it) {
            const double fx = f(x);
            (fx <= 0 ? hi : lo) = x;
            const double d1 = df(x);
            double next = d1 != 0 ? x - fx / d1 : 0.5 * (lo + hi);
            if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
            const bool done = std::abs(next - x) < 1e-8 || hi - lo < 1e-8;
            x = next;
            if (done) break;
        }
        s = x;
    }
    if (s < 0) return false;
    out.t = std::clamp(t0 + s * (t1 - t0), 0.0, 1.0);
    const Vec3 q = p0 + dp * s;
    Vec3 sum;
    for (int c = 0; c < 8; ++c) {
        const int dx = c & 1, dy = (c >> 1) & 1, dz = c >> 2;
        const double w = (dx ? q.x : 1 - q.x) * (dy ? q.y : 1 - q.y) * (dz ? q.z : 1 - q.z);
        sum += node_normal(brick, li + dx, lj + dy, lk + dz) * w;
    }
    out.normal = length(sum) > 0 ? normalize(sum) : Vec3{0, 0, 1};
    return true;
}

bool FieldView::march_brick(std::uint64_t brick, const std::array<int, 3>& b, const FieldSegment& g,
                            double t0, double t1, TableHit& out) const {
    std::array<int, 3> lo, hi;
    for (std::size_t ax = 0; ax < 3; ++ax) {
        lo[ax] = b[ax] * kBrick;
        hi[ax] = std::min(lo[ax] + kBrick, s_.nodes[ax] - 1);
    }
    const std::uint64_t mask = voxels_[brick];
    return traverse(g, 1.0, t0, t1, lo, hi, [&](const std::array<int, 3>& v, double ta, double tb) {
        const int bit = ((v[2] % kBrick) * kBrick + v[1] % kBrick) * kBrick + v[0] % kBrick;
        return ((mask >> bit) & 1) && voxel_root(brick, v, g, ta, tb, out);
    });
}

bool FieldView::march_group(const std::array<int, 3>& s, const FieldSegment& g, double t0,
                            double t1, TableHit& out) const {
    std::array<int, 3> lo, hi;
    for (std::size_t ax = 0; ax < 3; ++ax) {
        lo[ax] = s[ax] * kBrick;
        hi[ax] = std::min(lo[ax] + kBrick, bricks_[ax]);
    }
    const std::uint64_t mask = groups_[group_of(lo[0], lo[1], lo[2])];
    return traverse(g, double(kBrick), t0, t1, lo, hi,
                    [&](const std::array<int, 3>& b, double ta, double tb) {
                        if (!((mask >> brick_bit(b[0], b[1], b[2])) & 1)) return false;
                        const std::int64_t brick = dense_index(b[0], b[1], b[2]);
                        if (brick >= 0) return march_brick(std::uint64_t(brick), b, g, ta, tb, out);
                        if (!inside_brick(b[0], b[1], b[2])) return false;
                        out.t = ta;  // only where the fit left no dense brick at the surface
                        out.normal = normalize(-g.d);
                        return true;
                    });
}

bool FieldView::predict(Vec3 pa, Vec3 pb, TableHit& out) const {
    FieldSegment g;
    g.o = pa * inv_g_;
    g.d = (pb - pa) * inv_g_;
    for (std::size_t ax = 0; ax < 3; ++ax) g.inv[ax] = g.d[ax] != 0 ? 1 / g.d[ax] : 0;
    if (value_at(g.o, nullptr) <= 0) {  // the segment starts in the solid
        out.t = 0;
        value_at(g.o, &out.normal);
        return true;
    }
    return traverse(g, double(kBrick * kBrick), 0, 1, {0, 0, 0}, supers_,
                    [&](const std::array<int, 3>& s, double ta, double tb) {
                        return groups_[group_of(s[0] * kBrick, s[1] * kBrick, s[2] * kBrick)] !=
                                   0 &&
                               march_group(s, g, ta, tb, out);
                    });
}

}  // namespace lat
