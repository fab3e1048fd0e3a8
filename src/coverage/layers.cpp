#include "coverage/layers.h"

#include <algorithm>
#include <cmath>

namespace lat {

// The pixel's footprint on the surface, width / cos_v long across and width wide (cos_v: the
// camera ray's cosine with the normal), seen from the light (times cos_l) is an ellipse of
// area width^2 cos_l / cos_v; the isotropic filter of a lattice's level gets the width of the
// same area, within 1/4 to 4 times the camera's (kMaxShadowWidening; a surface seen edge-on).
// (Measured: bench/notes/filtering-constants.md.)
double shadow_width(Vec3 n, Vec3 camera_d, Vec3 shadow_d, double width) {
    const double cv = std::max(1.0 / 16, std::abs(dot(n, camera_d)) / length(camera_d));
    const double cl = std::abs(dot(n, shadow_d)) / length(shadow_d);
    return width * std::clamp(std::sqrt(cl / cv), 1 / kMaxShadowWidening, kMaxShadowWidening);
}

double seen_until(Vec3 camera_d, Vec3 shadow_d, double width, double distance) {
    const double c = -dot(camera_d, shadow_d) / (length(camera_d) * length(shadow_d));
    if (!(c > 0) || !(width > 0) || !(distance > 0)) return 0;
    const double s = std::sqrt(std::max(0.0, 1 - c * c));
    // Offset s * x from the line at x along the shadow ray; half-width (width / 2) (1 - c x /
    // distance) there.
    return 0.5 * width / (s + 0.5 * width * c / distance);
}

// A sheet of sub-rays covers the share of the footprint its coverage says, and its shadow rays'
// footprint is as wide as that share's area.
double sheet_width(double alpha, std::uint8_t sub_rays, double width) {
    return sub_rays == 0 ? width : width * std::sqrt(alpha);
}

double transmitted(std::span<const ObjectHit> partial) {
    LayerComposite through;
    for (const ObjectHit& h : partial) through.add(h.crossing);
    const double trans = through.left();
    return trans <= kMinTransmittance ? 0 : trans;
}

}  // namespace lat
