#include "render/camera.h"

#include <cmath>

namespace lat {

PinholeCamera::PinholeCamera(const Camera& c)
    : eye_(c.eye),
      h_(std::tan(c.fov_y_deg * M_PI / 360.0)),
      aspect_(static_cast<double>(c.width) / c.height),
      width_(c.width),
      height_(c.height) {
    w_ = normalize(c.look_at - c.eye);
    u_ = normalize(cross(w_, c.up));
    v_ = cross(u_, w_);
}

}  // namespace lat
