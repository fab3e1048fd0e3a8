// Quartic surfaces in images: no speckles or holes on a torus seen edge-on from far away, and a
// sphere written as a quartic renders like the sphere itself, silhouette (grazing rays) included.
#include <gtest/gtest.h>

#include "io/image_compare.h"
#include "render/modes/integrators.h"
#include "scene/scene_loader.h"

namespace lat {
namespace {

Image8 render_text(const std::string& json) {
    const Scene s = load_scene_text(json, "test.json");
    return render_exact(TracedScene(s), {}).display;
}

std::string scene(const std::string& camera, const std::string& object) {
    return R"({"camera": )" + camera + R"(,
      "background": [0, 0, 0], "shadows": true,
      "lights": [{"position": [30, -40, 50], "intensity": 0.8}, {"position": [-40, -10, 5], "intensity": 0.4}],
      "materials": {"m": {"color": [0.9, 0.7, 0.3], "ka": 0.2, "kd": 0.7, "ks": 0.5, "shininess": 25}},
      "objects": [)" + object + "]}";
}

// Pixels that differ from all four neighbours the same way (lit among background, or
// background among lit): the signature of lost or invented roots.
int isolated_pixels(const Image8& img) {
    auto lit = [&](int x, int y) {
        const std::size_t i = (static_cast<std::size_t>(y) * img.width + x) * 3;
        return img.rgb[i] + img.rgb[i + 1] + img.rgb[i + 2] > 0;
    };
    int n = 0;
    for (int y = 1; y + 1 < img.height; ++y)
        for (int x = 1; x + 1 < img.width; ++x) {
            const bool c = lit(x, y);
            if (lit(x - 1, y) != c && lit(x + 1, y) != c && lit(x, y - 1) != c && lit(x, y + 1) != c) ++n;
        }
    return n;
}

TEST(QuarticRender, TorusEdgeOnFromFarAwayHasNoSpecklesOrHoles) {
    // A torus (R = 1, r = 0.25) seen exactly edge-on from 2000 units: the root magnitudes
    // are 2000 while the tube is 0.5 thick, the hard case for a closed-form quartic solver.
    const std::string camera = R"({"eye": [0, -2000, 0], "look_at": [0, 0, 0], "up": [0, 0, 1],
        "fov_y_deg": 0.04, "width": 320, "height": 120})";
    const std::string torus = R"({"type": "torus", "major_radius": 1, "minor_radius": 0.25,
        "material": "m"})";
    const Image8 img = render_text(scene(camera, torus));
    int lit = 0;
    for (std::size_t i = 0; i < img.rgb.size(); i += 3) lit += img.rgb[i] > 0;
    EXPECT_GT(lit, 3000);
    EXPECT_EQ(isolated_pixels(img), 0);
    // And tilted 1 degree, where grazing rays pass through the hole and along the tube.
    const std::string tilted = R"({"type": "torus", "major_radius": 1, "minor_radius": 0.25,
        "axis": [0, -0.0174524, 0.9998477], "material": "m"})";
    EXPECT_EQ(isolated_pixels(render_text(scene(camera, tilted))), 0);
}

TEST(QuarticRender, SphereAsAQuarticMatchesTheSphere) {
    // (x^2+y^2+z^2)^2 = 1 has the unit sphere as its zero set and the same normals.
    const std::string camera = R"({"eye": [0, -300, 40], "look_at": [0, 0, 0], "up": [0, 0, 1],
        "fov_y_deg": 0.5, "width": 200, "height": 200})";
    const Image8 sphere = render_text(scene(camera, R"({"type": "sphere", "radius": 1, "material": "m"})"));
    const Image8 quartic = render_text(scene(camera, R"({"type": "quartic",
        "polynomial": "(x^2 + y^2 + z^2)^2 - 1", "material": "m"})"));
    const ImageDiffStats d = compare_images(sphere, quartic);
    EXPECT_GT(d.psnr_db, 60);
    EXPECT_EQ(d.pixels_over_8, 0);
}

}  // namespace
}  // namespace lat
