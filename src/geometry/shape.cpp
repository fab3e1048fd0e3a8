#include "geometry/shape.h"

#include <cmath>

namespace lat {

bool first_crossing(const SpanList& spans, double tmin, double tmax, Crossing& hit) {
    for (const Span& s : spans) {
        if (s.in.t >= tmax) return false;
        if (s.in.t > tmin && std::isfinite(s.in.t)) {
            hit = s.in;
            return true;
        }
        if (s.out.t > tmin && s.out.t < tmax && std::isfinite(s.out.t)) {
            hit = s.out;
            return true;
        }
    }
    return false;
}

}  // namespace lat
