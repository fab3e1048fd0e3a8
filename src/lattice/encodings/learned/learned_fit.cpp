#include "lattice/encodings/learned/learned_fit.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <cmath>

#include "lattice/bits/elias_fano.h"

namespace lat {
namespace {

constexpr std::uint64_t kMaxVoxels = std::uint64_t{1} << 27;
constexpr double kSearch = 2;     // node units: how far a node looks for its nearest point
constexpr double kNormalR = 0.5;  // node units: the disc around a node's foot point whose
                                  // normals it averages
constexpr int kSub = 4;           // points kept per voxel: one per sub-cell of kSub^3

using I3 = std::array<std::int64_t, 3>;

// The points, a spread subset of them bucketed by voxel.
class PointGrid {
public:
    PointGrid(std::span<const SurfacePoint> points, double g, const I3& nv) : g_(g), nv_(nv) {
        struct Keyed {
            std::uint64_t key;  // voxel * kSub^3 + sub-cell
            std::uint32_t index;
        };
        std::vector<Keyed> keyed(points.size());
        tbb::parallel_for(std::size_t{0}, points.size(), [&](std::size_t i) {
            const Vec3 q = points[i].p / g;
            I3 v{};
            std::uint64_t sub = 0;
            for (std::size_t ax = 3; ax-- > 0;) {
                v[ax] = std::clamp<std::int64_t>(std::int64_t(std::floor(q[ax])), 0, nv[ax] - 1);
                const auto s = std::clamp<std::int64_t>(
                    std::int64_t((q[ax] - double(v[ax])) * kSub), 0, kSub - 1);
                sub = sub * kSub + std::uint64_t(s);
            }
            keyed[i] = {id(v) * kSub * kSub * kSub + sub, static_cast<std::uint32_t>(i)};
        });
        tbb::parallel_sort(keyed.begin(), keyed.end(), [](const Keyed& x, const Keyed& y) {
            return x.key != y.key ? x.key < y.key : x.index < y.index;
        });
        first_.assign(std::uint64_t(nv[0] * nv[1] * nv[2]) + 1, 0);
        for (std::size_t i = 0; i < keyed.size(); ++i) {
            if (i > 0 && keyed[i].key == keyed[i - 1].key) continue;
            kept_.push_back(points[keyed[i].index]);
            ++first_[keyed[i].key / (kSub * kSub * kSub) + 1];
        }
        for (std::size_t v = 0; v + 1 < first_.size(); ++v) first_[v + 1] += first_[v];
    }

    std::uint64_t id(const I3& v) const {
        return std::uint64_t((v[2] * nv_[1] + v[1]) * nv_[0] + v[0]);
    }
    bool occupied(const I3& v) const { return first_[id(v)] != first_[id(v) + 1]; }

    // Calls f on every kept point in the voxels within `r` node units of p (node coordinates).
    template <class F>
    void near(Vec3 p, double r, F&& f) const {
        I3 lo, hi;
        for (std::size_t ax = 0; ax < 3; ++ax) {
            lo[ax] = std::max<std::int64_t>(0, std::int64_t(std::floor(p[ax] - r)));
            hi[ax] = std::min<std::int64_t>(nv_[ax] - 1, std::int64_t(std::floor(p[ax] + r)));
        }
        for (std::int64_t z = lo[2]; z <= hi[2]; ++z)
            for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
                for (std::int64_t x = lo[0]; x <= hi[0]; ++x) {
                    const std::uint64_t v = id({x, y, z});
                    for (std::uint32_t i = first_[v]; i < first_[v + 1]; ++i) f(kept_[i]);
                }
    }

    // A node's signed distance (lattice units) and normal: the tangent plane distance of its
    // nearest point, and the normals around its foot averaged (symmetric, so the error of any
    // one point's position cancels to first order). False when no point is within kSearch.
    bool fit_node(Vec3 x, double& d, Vec3& n) const {
        double best = kSearch * kSearch;
        const SurfacePoint* nearest = nullptr;
        near(x, kSearch, [&](const SurfacePoint& s) {
            const double d2 = length_squared(s.p / g_ - x);
            if (d2 < best) best = d2, nearest = &s;
        });
        if (!nearest) return false;
        d = dot(nearest->n, x * g_ - nearest->p);
        const Vec3 foot = x - nearest->n * (d / g_);
        n = nearest->n;
        // The normals around the foot as a linear function of the tangent-plane position
        // (weighted least squares): its value at the foot is right to first order even where
        // the points lie to one side. The disc grows until it holds enough points.
        Vec3 t1, t2;
        orthonormal_basis(nearest->n, t1, t2);
        for (double r = kNormalR; r <= kSearch; r *= 2) {
            double m[3][3] = {}, count = 0;
            Vec3 rhs[3];
            near(foot, r, [&](const SurfacePoint& s) {
                const Vec3 e = s.p / g_ - foot;
                const double r2 = length_squared(e) / (r * r);
                if (r2 >= 1 || dot(s.n, nearest->n) < 0.5) return;
                const double w = (1 - r2) * (1 - r2), row[3] = {1, dot(e, t1) / r, dot(e, t2) / r};
                for (int i = 0; i < 3; ++i) {
                    for (int j = 0; j < 3; ++j) m[i][j] += w * row[i] * row[j];
                    rhs[i] += s.n * (w * row[i]);
                }
                count += 1;
            });
            if (count < 6) continue;
            // Cramer's rule for the constant term; a near-singular spread falls back to the mean.
            const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                               m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
            Vec3 a = rhs[0] / m[0][0];
            if (det > 1e-6 * m[0][0] * m[0][0] * m[0][0])
                a = (rhs[0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     rhs[1] * (m[0][1] * m[2][2] - m[0][2] * m[2][1]) +
                     rhs[2] * (m[0][1] * m[1][2] - m[0][2] * m[1][1])) /
                    det;
            if (length(a) > 0) n = normalize(a);
            break;
        }
        return true;
    }

private:
    double g_;
    I3 nv_;
    std::vector<std::uint32_t> first_;  // per voxel, into kept_
    std::vector<SurfacePoint> kept_;
};

}  // namespace

std::vector<std::uint64_t> FieldFit::quantise(const FieldShape& s) const {
    BitWriter w(dense * s.brick_bits());
    for (std::size_t i = 0; i < dist.size(); ++i)
        w.put(s.encode_node(dist[i], normal[i]), static_cast<unsigned>(s.node_bits()));
    std::vector<std::uint64_t> out = w.words();
    out.resize(words_for_bits(dense * s.brick_bits()), 0);
    return out;
}

namespace {

// One fit, one step a method: the bricks near the points, the nodes fitted there, the signs
// spread to every node, and the bricks classified as dense (both signs) or of one sign.
class FieldFitter {
public:
    FieldFitter(const PointGrid& grid, FieldShape& s, const I3& nn)
        : grid_(grid), s_(s), nn_(nn), nv_{nn[0] - 1, nn[1] - 1, nn[2] - 1} {
        const auto nb3 = s.bricks();
        nb_ = {nb3[0], nb3[1], nb3[2]};
        nbricks_ = s.brick_count();
    }

    void fit(FieldFit& out) {
        find_candidates();
        fit_nodes();
        spread_signs();
        classify_bricks(out);
    }

private:
    const PointGrid& grid_;
    const FieldShape& s_;
    I3 nn_, nv_, nb_;  // nodes, voxels and bricks per axis
    std::uint64_t nbricks_ = 0;
    std::vector<std::uint8_t> candidate_;  // per brick
    std::vector<std::uint64_t> cand_;      // the candidate bricks' ids
    std::vector<double> dist_;             // per node of each candidate brick
    std::vector<Vec3> normal_;
    std::vector<std::uint8_t> known_;
    std::vector<std::int8_t> sign_;  // per node of the grid

    std::uint64_t brick_id(const I3& b) const {
        return std::uint64_t((b[2] * nb_[1] + b[1]) * nb_[0] + b[0]);
    }
    I3 brick_of(std::uint64_t id) const {
        return I3{std::int64_t(id % std::uint64_t(nb_[0])),
                  std::int64_t(id / std::uint64_t(nb_[0]) % std::uint64_t(nb_[1])),
                  std::int64_t(id / std::uint64_t(nb_[0] * nb_[1]))};
    }
    // The node of a brick's local node index, clamped to the grid (padding repeats the edge).
    I3 node_at(const I3& b, int node) const {
        const I3 l{node % (kBrick + 1), node / (kBrick + 1) % (kBrick + 1),
                   node / ((kBrick + 1) * (kBrick + 1))};
        I3 n;
        for (std::size_t ax = 0; ax < 3; ++ax) n[ax] = std::min(b[ax] * kBrick + l[ax], nn_[ax] - 1);
        return n;
    }
    std::uint64_t node_id(const I3& n) const {
        return std::uint64_t((n[2] * nn_[1] + n[1]) * nn_[0] + n[0]);
    }
    int sign_of(const I3& n) const { return sign_[node_id(n)] < 0 ? -1 : 1; }

    // Candidate bricks: those within a voxel of some point.
    void find_candidates() {
        candidate_.assign(nbricks_, 0);
        for (std::int64_t z = 0; z < nv_[2]; ++z)
            for (std::int64_t y = 0; y < nv_[1]; ++y)
                for (std::int64_t x = 0; x < nv_[0]; ++x) {
                    if (!grid_.occupied({x, y, z})) continue;
                    for (int c = 0; c < 27; ++c) {
                        const I3 v{x + c % 3 - 1, y + c / 3 % 3 - 1, z + c / 9 - 1};
                        if (v[0] < 0 || v[1] < 0 || v[2] < 0 || v[0] >= nv_[0] || v[1] >= nv_[1] ||
                            v[2] >= nv_[2])
                            continue;
                        candidate_[brick_id({v[0] / kBrick, v[1] / kBrick, v[2] / kBrick})] = 1;
                    }
                }
        for (std::uint64_t b = 0; b < nbricks_; ++b)
            if (candidate_[b]) cand_.push_back(b);
    }

    void fit_nodes() {
        dist_.assign(cand_.size() * kBrickNodes, 0.0);
        normal_.assign(cand_.size() * kBrickNodes, Vec3{0, 0, 1});
        known_.assign(cand_.size() * kBrickNodes, 0);
        tbb::parallel_for(std::size_t{0}, cand_.size(), [&](std::size_t k) {
            const I3 b = brick_of(cand_[k]);
            for (int node = 0; node < kBrickNodes; ++node) {
                const I3 n = node_at(b, node);
                const std::size_t i = k * kBrickNodes + std::size_t(node);
                double d;
                if (grid_.fit_node({double(n[0]), double(n[1]), double(n[2])}, d, normal_[i]))
                    dist_[i] = std::clamp(d, -s_.dmax, s_.dmax), known_[i] = 1;
            }
        });
    }

    // Signs of the nodes the fit reached, spread breadth-first (in index order: deterministic)
    // to all others; what no surface reaches is outside.
    void spread_signs() {
        sign_.assign(std::uint64_t(nn_[0] * nn_[1] * nn_[2]), 0);
        std::vector<std::uint64_t> queue;
        for (std::size_t k = 0; k < cand_.size(); ++k)
            for (int node = 0; node < kBrickNodes; ++node) {
                const std::size_t i = k * kBrickNodes + std::size_t(node);
                if (!known_[i]) continue;
                const std::uint64_t id = node_id(node_at(brick_of(cand_[k]), node));
                if (sign_[id] == 0) queue.push_back(id);
                sign_[id] = dist_[i] <= 0 ? -1 : 1;
            }
        std::sort(queue.begin(), queue.end());
        const std::uint64_t step[3] = {1, std::uint64_t(nn_[0]), std::uint64_t(nn_[0] * nn_[1])};
        for (std::size_t q = 0; q < queue.size(); ++q) {
            const std::uint64_t id = queue[q];
            const std::int64_t at[3] = {std::int64_t(id % step[1]),
                                        std::int64_t(id / step[1] % std::uint64_t(nn_[1])),
                                        std::int64_t(id / step[2])};
            for (std::size_t ax = 0; ax < 3; ++ax) {
                if (at[ax] > 0 && sign_[id - step[ax]] == 0)
                    sign_[id - step[ax]] = sign_[id], queue.push_back(id - step[ax]);
                if (at[ax] + 1 < nn_[ax] && sign_[id + step[ax]] == 0)
                    sign_[id + step[ax]] = sign_[id], queue.push_back(id + step[ax]);
            }
        }
    }

    // Dense bricks are the candidates with nodes of both signs: elsewhere the trilinear field
    // has no zero, and one sign bit says as much.
    void classify_bricks(FieldFit& out) {
        out.dense_bits.assign(words_for_bits(nbricks_), 0);
        out.sign_bits.assign(words_for_bits(nbricks_), 0);
        out.dist.clear();
        out.normal.clear();
        std::size_t k = 0;
        for (std::uint64_t b = 0; b < nbricks_; ++b) {
            const I3 bb = brick_of(b);
            bool neg = false, pos = false;
            if (candidate_[b]) {
                for (int node = 0; node < kBrickNodes; ++node) {
                    const std::size_t i = k * kBrickNodes + std::size_t(node);
                    if (!known_[i]) dist_[i] = sign_of(node_at(bb, node)) * s_.dmax;
                    (dist_[i] <= 0 ? neg : pos) = true;
                }
            }
            if (neg && pos) {
                out.dense_bits[b >> 6] |= std::uint64_t{1} << (b & 63);
                out.dist.insert(out.dist.end(), dist_.begin() + std::ptrdiff_t(k * kBrickNodes),
                                dist_.begin() + std::ptrdiff_t((k + 1) * kBrickNodes));
                out.normal.insert(out.normal.end(),
                                  normal_.begin() + std::ptrdiff_t(k * kBrickNodes),
                                  normal_.begin() + std::ptrdiff_t((k + 1) * kBrickNodes));
            } else if (candidate_[b] ? neg : sign_of(node_at(bb, kBrickNodes / 2)) < 0) {
                out.sign_bits[b >> 6] |= std::uint64_t{1} << (b & 63);
            }
            k += candidate_[b];
        }
        out.dense = out.dist.size() / kBrickNodes;
    }
};

}  // namespace

bool fit_field(std::span<const SurfacePoint> points, std::array<int, 3> cells, double g,
               FieldFit& out) {
    FieldShape& s = out.shape;
    s.g = g;
    s.dmax = kSearch * g;
    I3 nn{};  // nodes per axis
    for (std::size_t ax = 0; ax < 3; ++ax) {
        s.nodes[ax] = static_cast<int>(std::ceil(cells[ax] / g - 1e-9)) + 1;
        nn[ax] = s.nodes[ax];
    }
    if (nn[0] * nn[1] * nn[2] > std::int64_t(kMaxVoxels)) return false;
    const PointGrid grid(points, g, I3{nn[0] - 1, nn[1] - 1, nn[2] - 1});
    FieldFitter(grid, s, nn).fit(out);
    return true;
}

}  // namespace lat
