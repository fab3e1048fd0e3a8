#pragma once
// An independent, brute-force renderer for "lattice-reference/1" scenes, written from the
// format's README (examples/ ships the scenes; the README defines camera, solids and shading).
// It shares no code with src/ on purpose: it is the yardstick the project's renderer is checked
// against, so a misreading of the format there must not be inherited here. Everything is
// computed in long double, every object is tested for every ray (only a bounding box per object
// culls), and each pixel is one ray through its centre.
#include <cstdint>
#include <string>
#include <vector>

namespace reftrace {

using Real = long double;

struct Vec {
    Real x = 0, y = 0, z = 0;
};

struct Camera {
    Vec eye, look_at, up;
    Real fov_y_deg = 0;
    int width = 0, height = 0;
};

struct Light {
    Vec position, intensity;
};

struct Material {
    Vec color;
    Real ka = 0, kd = 0, ks = 0, shininess = 0;
};

struct Ball {
    Vec c;
    Real r = 0;
};

// Flat-ended cylinder: axis from `a` along the unit vector `axis` for `length`, radius `r`.
struct Cylinder {
    Vec a, axis;
    Real length = 0, r = 0;
};

// The union of its balls and cylinders, in the primitive's own coordinates.
struct Primitive {
    std::vector<Ball> balls;
    std::vector<Cylinder> cylinders;
    Vec lo, hi;  // a box around all of them
};

enum class Kind { sphere, halfspace, instance };

struct Object {
    Kind kind = Kind::sphere;
    int material = 0;
    Ball ball;           // sphere
    Vec point, normal;   // halfspace: dot(x - point, normal) <= 0, normal of unit length
    int primitive = -1;  // instance
    Real m[3][3] = {};   // instance: world = m * local + t
    Vec t;
    Real minv[3][3] = {};
    Vec lo, hi;  // world box (instances only; spheres and halfspaces are tested directly)
};

struct Scene {
    Camera camera;
    Vec background, ambient;
    bool shadows = false;
    std::vector<Light> lights;
    std::vector<Material> materials;
    std::vector<Primitive> primitives;
    std::vector<Object> objects;
};

// Throws std::runtime_error naming the file and the place of anything missing or malformed.
Scene load_scene(const std::string& path);
Scene parse_scene(const std::string& json_text, const std::string& name = "scene");

// 8-bit RGB, row-major, row 0 at the top: round(255 * clamp(c, 0, 1)).
struct Image {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;
};

// threads <= 0 means one per hardware thread; rows are shared out between them.
// The full image at the camera's resolution.
Image render(const Scene& scene, int threads = 0);
// The same view (same fov_y) at w x h pixels.
Image render_resized(const Scene& scene, int w, int h, int threads = 0);
// Only pixels [x0, x0 + w) x [y0, y0 + h) of the full-resolution image.
Image render_window(const Scene& scene, int x0, int y0, int w, int h, int threads = 0);

// What one pixel's ray found, for explaining differences.
struct PixelTrace {
    bool hit = false;
    int object = -1;               // index into Scene::objects
    int component = -1;            // instances: ball k is k, cylinder k is balls.size() + k
    Real t = 0;                    // along the unit ray direction
    Vec p, n;                      // hit point; unit normal facing the viewer
    std::vector<char> light_seen;  // per light: 1 if the hit point sees it
    Vec color;                     // unclamped
};
PixelTrace trace_pixel(const Scene& scene, int width, int height, int i, int j);

// Shadow rays start this far (world units) from the hit point, so that the surface just hit is
// not found again through rounding. In long double, positions in these scenes (|x| < 1000) are
// off by ~1e-16 at most, so 1e-9 is far above rounding yet far below any feature size; a light
// is taken as hidden only by solids the segment enters more than 1e-9 away from the hit point.
inline constexpr Real kShadowEpsilon = 1e-9L;

}  // namespace reftrace
