#include "coverage/layer_composite.h"

namespace lat {

double LayerComposite::add(double coverage, std::uint8_t sub_rays) {
    const double before = left();
    if (sub_rays == 0) {
        free_ *= 1.0 - coverage;
        ++draws_;
    } else {
        covered_ |= sub_rays;
    }
    return before > 0 ? 1.0 - left() / before : 1.0;
}

}  // namespace lat
