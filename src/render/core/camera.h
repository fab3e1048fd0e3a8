#pragma once
// The pinhole camera of the reference format (docs/scene-format.md): pixel (i, j), row 0
// at the top, sample offset (sx, sy) in [0, 1) with (0.5, 0.5) the pixel centre. It makes the
// rays the renderer traces, with their footprints: the one home of the pixel's spread.
#include "math/ray.h"
#include "scene/scene.h"

namespace lat {

// A ray as the renderer traces it: its line, and what it stands for beyond it (RayFootprint):
// the width and spread of its footprint, its directions across, and its purpose, a camera
// ray's colour or a shadow ray's transmittance (which wants only coverage). The accelerator
// hands each object its own copy of the footprint (accel/embree_query.h).
struct TraceRay {
    enum class Purpose { kCamera, kShadow };

    Vec3 o, d;  // d of unit length
    RayFootprint footprint;

    Purpose purpose() const {
        return footprint.coverage_only ? Purpose::kShadow : Purpose::kCamera;
    }
    // The ray with its footprint, for queries (pointing at this value: not to outlive it).
    Ray ray() const { return {o, d, &footprint}; }
    // Its line alone, for queries and shading that want no footprint.
    Ray line() const { return {o, d}; }

    // A shadow ray along r (unit direction) leaving a surface where its footprint is `width`
    // wide, narrowing to the point light `dist` away.
    // seen_until: RayFootprint's.
    static TraceRay shadow(const Ray& r, double width, double dist, double seen_until) {
        TraceRay t{r.o, r.d, footprint_across(normalize(r.d), width, -width / dist, true)};
        t.footprint.seen_until = seen_until;
        return t;
    }
};

class PinholeCamera {
public:
    // spp: the samples that split each pixel, and so its footprint.
    explicit PinholeCamera(const Camera& c, int spp = 1);

    // A camera sample's line.
    Ray ray(double i, double j, double sx = 0.5, double sy = 0.5) const {
        const double px = (2.0 * (i + sx) / width_ - 1.0) * aspect_ * h_;
        const double py = (1.0 - 2.0 * (j + sy) / height_) * h_;
        return {eye_, normalize(w_ + u_ * px + v_ * py)};
    }
    // A camera sample as traced: its line and its footprint (no width at the eye, spread()).
    TraceRay trace_ray(double i, double j, double sx = 0.5, double sy = 0.5) const {
        const Ray r = ray(i, j, sx, sy);
        return {r.o, r.d, footprint_across(normalize(r.d), 0, spread_, false)};
    }
    // A sample's footprint per unit distance along its ray: the pixel's angle, shared by the
    // spp samples that split it. Lattice levels of detail and sub-ray bounds are planned with
    // it (render/render_modes.cpp) before the render traces with it.
    double spread() const { return spread_; }

private:
    Vec3 eye_, u_, v_, w_;
    double h_, aspect_;
    double width_, height_;
    double spread_;
};

}  // namespace lat
