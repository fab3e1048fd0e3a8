#pragma once
// Sheets: the surfaces a camera ray meets in one shape through partial coverage. A shape whose
// answer to a ray is more than its closest crossing (a lattice answered by its sub-rays: a
// tuft's strands one behind the other) offers them through SheetSource; every other shape's
// one sheet is its closest crossing (sheets_of).
#include <array>
#include <cstdint>
#include <span>
#include <type_traits>

#include "geometry/shape.h"

namespace lat {

// The unit normals (shape space) of the sub-rays a sheet is made of: the renderer averages
// their shading terms, where a mean normal's would blur a hair's highlight and terminator
// across the pixel. count 0 for every other crossing.
// Only n[0, count) is meant: the rest is left unset. Every camera sample makes a SurfaceHit and
// every query an ObjectHit, each holding one of these, and zeroing its 96 bytes (a `rep stos`)
// on every one is a large part of a cheap camera ray's cost.
struct SubRayNormals {
    SubRayNormals() {}  // user-provided, so that `{}` too leaves n unset
    std::uint8_t count = 0;
    // A Vec3 whose default construction leaves it unset.
    struct Slot {
        double x, y, z;
        Slot() = default;
        Slot(Vec3 v) : x(v.x), y(v.y), z(v.z) {}  // NOLINT: a Vec3 stored as it is
        operator Vec3() const { return {x, y, z}; }  // NOLINT: read as the Vec3 it holds
    };
    std::array<Slot, 4> n;
};
// Copied whole as bytes, unset slots too; a Slot default-constructed is left unset.
static_assert(std::is_trivially_copyable_v<SubRayNormals>);
static_assert(std::is_trivially_default_constructible_v<SubRayNormals::Slot>);

// One of a camera ray's sheets.
struct SheetCrossing {
    Crossing crossing;
    SubRayNormals normals;
};

// At most this many sheets a ray in one shape.
inline constexpr int kMaxSheets = 4;

// A shape's sheets, for shapes that have more than their closest crossing to give.
class SheetSource {
public:
    // A camera ray's surfaces through partial coverage: at most kMaxSheets crossings with
    // tmin < t < tmax, in ray order; returns how many. Each is shaded as its own surface, with
    // its sub-rays' normals.
    virtual int sheets(const Ray& r, double tmin, double tmax,
                       std::span<SheetCrossing, kMaxSheets> out) const = 0;

protected:
    ~SheetSource() = default;
};

// The shape's SheetSource, if it offers one (asked once per object, not per ray).
inline const SheetSource* sheet_source(const Shape& s) {
    return dynamic_cast<const SheetSource*>(&s);
}

// The sheets of shape s, whose sheet_source is `source`: its own, or its closest crossing.
inline int sheets_of(const Shape& s, const SheetSource* source, const Ray& r, double tmin,
                     double tmax, std::span<SheetCrossing, kMaxSheets> out) {
    if (source) return source->sheets(r, tmin, tmax, out);
    out[0].normals.count = 0;
    return s.intersect(r, tmin, tmax, out[0].crossing) ? 1 : 0;
}

}  // namespace lat
