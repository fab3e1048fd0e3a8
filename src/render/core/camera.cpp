#include "render/core/camera.h"

#include <algorithm>
#include <cmath>

namespace lat {

PinholeCamera::PinholeCamera(const Camera& c, int spp)
    : eye_(c.eye),
      h_(std::tan(c.fov_y_deg * M_PI / 360.0)),
      aspect_(static_cast<double>(c.width) / c.height),
      width_(c.width),
      height_(c.height),
      spread_(2 * std::tan(c.fov_y_deg * M_PI / 360.0) / c.height /
              std::sqrt(double(std::max(1, spp)))) {
    w_ = normalize(c.look_at - c.eye);
    u_ = normalize(cross(w_, c.up));
    v_ = cross(u_, w_);
}

}  // namespace lat
