#include "geometry/shape.h"

#include <algorithm>
#include <cmath>

#include "math/float_round.h"

namespace lat {

Bounds3 Capsule::placed_bounds(const Transform& xf) const {
    const Affine& m = xf.forward();
    Vec3 e;
    for (std::size_t i = 0; i < 3; ++i) e[i] = r * length(m.m.r[i]);
    const Vec3 pa = xf.point(a), pb = xf.point(b);
    return {min(pa, pb) - e, max(pa, pb) + e};
}

// Moving the ends by at most `moved` moves every point of the segment by no more (each is a
// convex combination of them), so the distance from any line to it by no more.
FloatCapsule FloatCapsule::holding(const Capsule& c) {
    FloatCapsule f;
    double moved = 0;
    for (std::size_t k = 0; k < 3; ++k) {
        f.a[k] = static_cast<float>(c.a[k]), f.b[k] = static_cast<float>(c.b[k]);
        moved = std::max({moved, std::abs(double(f.a[k]) - c.a[k]),
                          std::abs(double(f.b[k]) - c.b[k])});
    }
    const double r = c.r + std::sqrt(3.0) * moved;
    f.r = float_at_least(r);
    if (!std::isfinite(moved) || !std::isfinite(f.r)) f.r = -1;  // beyond float: none
    return f;
}

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

void merge_span_union(SpanList& spans, std::size_t first) {
    auto begin = spans.begin() + static_cast<std::ptrdiff_t>(first);
    std::sort(begin, spans.end(), [](const Span& a, const Span& b) { return a.in.t < b.in.t; });
    std::size_t w = first;
    for (std::size_t k = first; k < spans.size(); ++k) {
        if (w > first && spans[k].in.t <= spans[w - 1].out.t) {
            if (spans[k].out.t > spans[w - 1].out.t) spans[w - 1].out = spans[k].out;
        } else {
            spans[w++] = spans[k];
        }
    }
    spans.resize(w);
}

Crossing nearest_crossing(const Shape& shape, const Ray& r) {
    SpanList spans;
    shape.spans(r, spans);
    Crossing best{kInfinity, 0, 0};
    for (const Span& sp : spans)
        for (const Crossing& c : {sp.in, sp.out})
            if (std::abs(c.t) < std::abs(best.t)) best = c;
    best.t = 0;
    return best;
}

}  // namespace lat
