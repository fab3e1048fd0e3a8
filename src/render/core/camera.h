#pragma once
// The pinhole camera of the reference format (docs/scene-format.md): pixel (i, j), row 0
// at the top, sample offset (sx, sy) in [0, 1) with (0.5, 0.5) the pixel centre.
#include "math/ray.h"
#include "scene/scene.h"

namespace lat {

// A camera sample's footprint per unit distance along its ray: the pixel's angle, shared by
// the spp samples that split it. The one home of the footprint's spread: the renderer traces
// with it, and lattice levels of detail and sub-ray bounds are planned with it.
double sample_spread(const Camera& c, int spp);

class PinholeCamera {
public:
    explicit PinholeCamera(const Camera& c);

    Ray ray(double i, double j, double sx = 0.5, double sy = 0.5) const {
        const double px = (2.0 * (i + sx) / width_ - 1.0) * aspect_ * h_;
        const double py = (1.0 - 2.0 * (j + sy) / height_) * h_;
        return {eye_, normalize(w_ + u_ * px + v_ * py)};
    }

private:
    Vec3 eye_, u_, v_, w_;
    double h_, aspect_;
    double width_, height_;
};

}  // namespace lat
