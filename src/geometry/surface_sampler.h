#pragma once
// Area-uniform random points on surfaces, for scattering instances over them (scene/scatter):
// the named quadrics and the torus through a parametrisation with rejection by the area
// element, triangle meshes by picking a triangle in proportion to its area. Everything is in
// world coordinates (the surface's transform applied), draws come from a CounterRng, and no
// std distribution is used, so samples are the same bytes on every machine.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry/triangle_mesh.h"
#include "math/bounds.h"
#include "math/transform.h"
#include "util/counter_rng.h"

namespace lat {

struct SurfaceSample {
    Vec3 p;  // on the surface
    Vec3 n;  // unit normal: outward for solids, the mesh's shading normal for meshes
};

class SurfaceSampler {
public:
    virtual ~SurfaceSampler() = default;
    // World area of the region sampled.
    virtual double area() const = 0;
    // One area-uniform sample.
    virtual SurfaceSample sample(CounterRng& rng) const = 0;
    // A box holding every sample (world coordinates; up to rounding for meshes).
    virtual Bounds3 bounds() const = 0;
};

// Canonical surfaces (axis along z), placed in the world by `xf`; the named shapes' semi-axes go
// into xf as a scale.
enum class ParamKind {
    kSphere,        // unit sphere
    kCylinder,      // x² + y² = 1
    kCone,          // x² + y² = z² (both nappes)
    kParaboloid,    // x² + y² = z
    kHyperboloid1,  // x² + y² - z² = 1
    kHyperboloid2,  // x² + y² - z² = -1 (both sheets)
    kTorus,         // major radius 1, minor radius `minor`
    kPlane,         // z = 0, normal +z
};

// Whether the surface needs a box to have finite area.
bool param_kind_unbounded(ParamKind k);

// A sampler for the surface clipped to `box` (world coordinates; needed for unbounded kinds).
// Throws InputError(what) when the clipped area is zero or so small a part of the region the
// sampler must search that sampling would be slow (messages without location: callers add it).
std::unique_ptr<SurfaceSampler> make_param_sampler(ParamKind kind, double minor,
                                                   const Transform& xf,
                                                   const std::optional<Bounds3>& box);

// Throws InputError(what), without location, when the placed mesh has no area or too much.
std::unique_ptr<SurfaceSampler> make_mesh_sampler(std::shared_ptr<const TriangleMeshShape> mesh,
                                                  const Transform& xf);

}  // namespace lat
