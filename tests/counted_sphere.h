#pragma once
// A sphere that counts the tests it is asked for (intersect and occluded): what the
// accelerator's culling let through to it.
#include "geometry/sphere.h"

namespace lat::test {

class CountedSphere final : public Shape {
public:
    CountedSphere(Vec3 c, double r) : s_(c, r) {}
    Bounds3 bounds() const override { return s_.bounds(); }
    bool intersect(const Ray& r, double tmin, double tmax, Crossing& hit) const override {
        ++tests;
        return s_.intersect(r, tmin, tmax, hit);
    }
    bool occluded(const Ray& r, double tmin, double tmax) const override {
        ++tests;
        return s_.occluded(r, tmin, tmax);
    }
    void spans(const Ray& r, SpanList& out) const override { s_.spans(r, out); }
    Vec3 normal(const Ray& r, const Crossing& c) const override { return s_.normal(r, c); }
    bool inside(Vec3 p) const override { return s_.inside(p); }

    mutable int tests = 0;

private:
    SphereShape s_;
};

}  // namespace lat::test
