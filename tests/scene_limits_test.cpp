// Hostile scenes: numbers beyond double range, deep nesting, overflowing transforms
// and coefficients, and sizes over the limits each give one InputError naming the file and the
// place; an extreme quartic renders without handing a non-finite ray to Embree.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "geometry/polynomial_parser.h"
#include "input_error.h"
#include "render/modes/integrators.h"
#include "scene/object_parser.h"
#include "scene/scene_loader.h"

namespace lat {
namespace {

using test::error_of;

// A one-object scene; `object` is the JSON of the object, `camera_extra` goes into the camera.
std::string scene_with(const std::string& object, const std::string& fov = "40",
                       const std::string& size = "\"width\": 8, \"height\": 6") {
    return R"({"camera": {"eye": [0, -6, 1], "look_at": [0, 0, 0], "fov_y_deg": )" + fov + ", " +
           size + R"(},
  "lights": [{"position": [4, -5, 6]}],
  "materials": {"m": {"color": [0.8, 0.5, 0.3]}},
  "objects": [)" +
           object + "]}";
}

const char* kSphere = R"({"type": "sphere", "radius": 1, "material": "m"})";

std::string load_error(const std::string& text) {
    return error_of([&] { load_scene_text(text, "scene.json"); });
}

// A CSG union nested `depth` levels deep around one sphere.
std::string nested_csg(int depth) {
    std::string s;
    for (int i = 0; i < depth; ++i) s += R"({"type": "csg", "op": "union", "children": [)";
    s += R"({"type": "sphere", "radius": 1})";
    for (int i = 0; i < depth; ++i) s += "]}";
    return s;
}

TEST(SceneLimits, NumberBeyondDoubleRangeIsOneLocatedError) {
    const std::string msg = load_error(scene_with(kSphere, "1e400"));
    EXPECT_EQ(msg, "scene.json:1:67: number 1e400 is out of the range of a double");
    EXPECT_NE(load_error(scene_with(kSphere, "-1e400")).find("number -1e400 is out of"),
              std::string::npos);
    // Underflow is harmless: the value is 0 and the range check says so.
    EXPECT_EQ(load_error(scene_with(kSphere, "1e-400")),
              "scene.json: camera.fov_y_deg: must be between 0 and 180 degrees");
}

TEST(SceneLimits, NumbersInsideStringsAreNotNumbers) {
    const std::string obj =
        R"({"type": "sphere", "radius": 1, "material": "m", "note": "1e400 [[["})";
    EXPECT_EQ(load_error(scene_with(obj)), "");
}

TEST(SceneLimits, DeepJsonNestingIsRefusedBeforeParsing) {
    const std::string deep(100000, '[');
    EXPECT_EQ(load_error(deep), "scene.json:1:" + std::to_string(kMaxJsonDepth + 1) +
                                    ": invalid JSON: nested deeper than " +
                                    std::to_string(kMaxJsonDepth) + " levels");
}

TEST(SceneLimits, CsgDepthLimit) {
    auto with_material = [](std::string csg) { return csg.insert(1, R"("material": "m", )"); };
    EXPECT_EQ(load_error(scene_with(with_material(nested_csg(kMaxCsgDepth - 1)))), "");
    const std::string msg = load_error(scene_with(with_material(nested_csg(kMaxCsgDepth))));
    EXPECT_NE(msg.find("scene.json: objects[0].children[0]"), std::string::npos) << msg;
    EXPECT_NE(msg.find(": csg tree nested deeper than 256 levels"), std::string::npos) << msg;
    // Thousands of levels: stopped by the JSON depth limit, without recursing that deep.
    EXPECT_NE(load_error(scene_with(with_material(nested_csg(5000)))).find("nested deeper than"),
              std::string::npos);
}

TEST(SceneLimits, OverflowingTransformIsRefused) {
    const std::string obj = R"({"type": "sphere", "radius": 1, "material": "m",
        "transform": [{"scale": 1e200}, {"scale": 1e200}]})";
    EXPECT_EQ(load_error(scene_with(obj)),
              "scene.json: objects[0].transform: the transform overflows the range of a double "
              "(or its inverse does)");
    // Each level finite, the composition down the tree not.
    const std::string csg = R"({"type": "csg", "op": "union", "material": "m",
        "transform": [{"scale": 1e200}],
        "children": [{"type": "sphere", "radius": 1, "transform": [{"scale": 1e200}]}]})";
    EXPECT_EQ(load_error(scene_with(csg)).find("scene.json: objects[0].children[0]: the transform"),
              0u);
    // A tiny scale whose inverse overflows.
    const std::string tiny = R"({"type": "sphere", "radius": 1, "material": "m",
        "transform": [{"scale": 1e-200}, {"scale": 1e-200}]})";
    EXPECT_NE(load_error(scene_with(tiny)).find("overflows"), std::string::npos);
}

TEST(SceneLimits, QuarticCoefficientsThatSumToInfinityAreRefused) {
    const std::string obj = R"({"type": "quartic", "material": "m",
        "coefficients": [[2, 0, 0, 1], [0, 0, 0, 1e308], [0, 0, 0, 1e308]]})";
    EXPECT_EQ(load_error(scene_with(obj)),
              "scene.json: objects[0].coefficients[2]: the coefficients of x^0 y^0 z^0 add up "
              "beyond the range of a double");
    const std::string text = R"({"type": "quartic", "material": "m",
        "polynomial": "(x^2 + 1e200)^2 - 1"})";
    EXPECT_NE(load_error(scene_with(text)).find("objects[0].polynomial: column"),
              std::string::npos);
}

TEST(SceneLimits, PolynomialLengthLimit) {
    std::string p = "x";
    while (p.size() <= kMaxPolynomialLength) p += " + x";
    const std::string obj = R"({"type": "quartic", "material": "m", "polynomial": ")" + p + "\"}";
    EXPECT_NE(load_error(scene_with(obj)).find("objects[0].polynomial: column 10001: the text is "),
              std::string::npos);
    EXPECT_NE(load_error(scene_with(obj)).find("over the limit of 10000"), std::string::npos);
}

TEST(SceneLimits, ImageSizeLimits) {
    EXPECT_EQ(load_error(scene_with(kSphere, "40", "\"width\": 32768, \"height\": 32768")),
              "scene.json: camera: 32768 x 32768 pixels is over the limit of 67108864 pixels");
    const Scene s = load_scene_text(scene_with(kSphere, "40", "\"width\": 4096, \"height\": 4096"),
                                    "scene.json");
    EXPECT_EQ(error_of([&] { check_render_budget(s.camera, 256, "scene.json"); }), "");
    EXPECT_EQ(error_of([&] { check_render_budget(s.camera, 257, "scene.json"); }),
              "scene.json: camera: 4096 x 4096 pixels x 257 samples per pixel is over the limit "
              "of 4294967296 samples");
}

// Reproducer of the SIGABRT: the quartic's restriction to a ray overflows, hit points and
// shadow rays became NaN, and Embree's ray.valid() assertion aborted.
TEST(SceneLimits, ExtremeQuarticRendersWithoutCrashing) {
    const std::string obj = R"({"type": "quartic", "material": "m",
        "polynomial": "(x^2+y^2+z^2)^2 - 1e308"}, {"type": "sphere", "radius": 1, "material": "m"})";
    const Scene s = load_scene_text(scene_with(obj), "scene.json");
    const TracedScene rs(s);
    const RenderOutput out = render_exact(rs, {});
    EXPECT_EQ(out.display.rgb.size(), 8u * 6u * 3u);
}

TEST(SceneLimits, CameraDistanceMustNotOverflow) {
    const std::string text = scene_with(kSphere);
    std::string far = text;
    far.replace(far.find("[0, -6, 1]"), 10, "[0, -1e200, 1]");
    EXPECT_EQ(load_error(far),
              "scene.json: camera: eye and look_at are too far apart (the "
              "distance overflows a double)");
}

// Bounds beyond Embree's float range used to drop the object silently: it is now tested
// outside Embree, like unbounded objects.
TEST(SceneLimits, ObjectsBeyondFloatRangeAreStillHit) {
    const Scene s = load_scene_text(
        scene_with(R"({"type": "sphere", "center": [0, 1e19, 0], "radius": 0.99999999999e19,
                       "material": "m"})"),
        "scene.json");
    const TracedScene rs(s);
    SurfaceHit hit;
    EXPECT_TRUE(rs.intersect({{0, -6, 0}, {0, 1, 0}}, 0, kInfinity, hit));
}

TEST(SceneLimits, NonFiniteRaysMiss) {
    const Scene s = load_scene_text(scene_with(kSphere), "scene.json");
    const TracedScene rs(s);
    SurfaceHit hit;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(rs.intersect({{nan, -6, 0}, {0, 1, 0}}, 0, kInfinity, hit));
    EXPECT_FALSE(rs.intersect({{0, -6, 0}, {0, kInfinity, 0}}, 0, kInfinity, hit));
    EXPECT_FALSE(rs.intersect({{0, -6, 0}, {0, 1, 0}}, nan, kInfinity, hit));
    // Beyond Embree's float range but finite: bounded objects are out of reach, no abort.
    EXPECT_FALSE(rs.intersect({{0, -1e19, 0}, {0, 1, 0}}, 0, kInfinity, hit));
    EXPECT_TRUE(rs.intersect({{0, -6, 0}, {0, 1, 0}}, 0, kInfinity, hit));
}

}  // namespace
}  // namespace lat
