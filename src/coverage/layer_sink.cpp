#include "coverage/layer_sink.h"

#include <algorithm>
#include <cassert>

namespace lat {

bool LayerSink::met_already(std::uint32_t object) const {
    for (const ObjectHit& p : partial_)
        if (p.object == object) return true;
    return false;
}

bool LayerSink::add_shadow(const ObjectHit& h) {
    assert(stop_.shadow());
    if (met_already(h.object)) return false;
    partial_.push_back(h);
    transmitted_.add(h.crossing);
    return transmitted_.left() < stop_.blocked_below * (1 - 1e-9);
}

bool LayerSink::add_camera(const ObjectHit& h, double& tmax) {
    assert(!stop_.shadow());
    partial_.insert(std::upper_bound(partial_.begin(), partial_.end(), h, in_ray_order), h);
    if (stop_.max_layers <= 0) return false;
    LayerComposite seen;
    for (std::size_t i = 0; i < partial_.size(); ++i) {
        seen.add(partial_[i].crossing);
        if (seen.draws() == stop_.max_layers || seen.left() <= stop_.min_left) {
            partial_.resize(i + 1);
            tmax = std::min(tmax, partial_.back().t);
            return true;
        }
    }
    return false;
}

void LayerSink::finish(bool found, double opaque_t) {
    if (found) std::erase_if(partial_, [&](const ObjectHit& p) { return p.t >= opaque_t; });
    std::sort(partial_.begin(), partial_.end(), in_ray_order);
}

}  // namespace lat
