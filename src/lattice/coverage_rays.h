#pragma once
// The sub-rays of one pair (see lattice/coverage.h), and which of them are the pair's own: the
// rays LatticeFrame::snap takes back to the pair. Building a coverage table asks that of billions
// of sub-rays; most of them lie where the rounding of snap cannot go either way, and there the
// answer follows from the sub-ray's ends alone (tested against snap on every sub-ray of a
// lattice).
#include <algorithm>
#include <array>
#include <cstddef>

#include "lattice/boundary_grid.h"
#include "math/vec.h"

namespace lat {

struct SubRay {
    Vec3 p, q;  // lattice units
};

// What the sub-rays of the pair (p, q) share: the segment and the axes of the faces it crosses.
class PairRays {
public:
    PairRays(const BoundaryGrid& grid, const GridPoint& p, const GridPoint& q);

    // The segment shifted by (du, dv) cells along the entry face's next two axes (x -> y, z;
    // y -> z, x; z -> x, y), from the entry face's plane to the exit face's, its ends kept on
    // the box.
    SubRay ray(double du, double dv) const {
        Vec3 shift;
        shift[u_axis()] = du;
        shift[v_axis()] = dv;
        // The shifted line leaves through the plane of q's face where it meets it.
        Vec3 e = vq_ + shift;
        if (d_[aq_] != 0) e = e - d_ * (shift[aq_] / d_[aq_]);
        return {clamp_to_box(vp_ + shift), clamp_to_box(e)};
    }

    const Vec3& from() const { return vp_; }
    const Vec3& dir() const { return d_; }  // q - p
    // The axes along which du and dv shift.
    std::size_t u_axis() const { return static_cast<std::size_t>(kFaceAxes[ap_][0]); }
    std::size_t v_axis() const { return static_cast<std::size_t>(kFaceAxes[ap_][1]); }
    // How far any point of a sub-ray with |du|, |dv| <= 1/2 can lie from the line p q: a
    // shifted line is |shift| <= sqrt(2)/2 from it, and clamping the exit onto the box moves it
    // by at most as much as the exit moved from q.
    double reach() const;

    // Whether snap takes the sub-ray to this pair: kUnsure where the ends lie too close to a
    // rounding boundary, the box's edges, or the direction too close to a face's plane for the
    // answer to be certain; ask LatticeFrame::snap then.
    enum class Snap { kOther, kPair, kUnsure };
    Snap guess_snap(const SubRay& s) const;

private:
    Vec3 clamp_to_box(Vec3 v) const {
        for (std::size_t k = 0; k < 3; ++k) v[k] = std::clamp(v[k], 0.0, double(n_[k]));
        return v;
    }

    std::array<int, 3> n_;
    GridPoint gq_;
    Vec3 vp_, vq_, d_;
    std::size_t ap_, aq_;  // the axes of the faces of p and q the segment crosses most squarely
};

}  // namespace lat
