// Lattice mode against exact mode on the paper's plates (small renders): the lattice is close
// to exact and gets closer when refined; lattices shadow each other in Plate 2, not in Plate 1.
#include <gtest/gtest.h>

#include "io/image_compare.h"
#include "render/renderer.h"
#include "scene/lattice_tables.h"
#include "scene/scene_loader.h"
#include "temp_dir.h"
#include "test_paths.h"

namespace lat {
namespace {

Scene small(const char* name, int size) {
    Scene s = load_scene(test::source_path(std::string("examples/") + name + ".json"));
    s.camera.width = s.camera.height = size;
    return s;
}

Image8 render_exact(const Scene& s) { return render_image(RenderScene(s), {}).display; }

Image8 render_lattice(const Scene& s, const TableCache& cache, int sigma_inv) {
    const SceneLattices l = scene_lattices(s, cache, sigma_inv, "hash14", false);
    const RenderScene rs(s, [&](int p) { return l.shapes[static_cast<std::size_t>(p)]; });
    return render_image(rs, {}).display;
}

class LatticeRender : public ::testing::Test {
protected:
    test::TempDir dir;
    TableCache cache{dir.path().string(), true};
};

TEST_F(LatticeRender, PlatesAreCloseToExact) {
    struct Case {
        const char* plate;
        double min_psnr;
    };
    for (const Case c : {Case{"plate1-thistle-no-self-shading", 20}, Case{"plate3-hair-closeup", 28},
                         Case{"plate4-fuzzy-sphere-1000", 20}}) {
        const Scene s = small(c.plate, 128);
        const ImageDiffStats d = compare_images(render_exact(s), render_lattice(s, cache, 1));
        EXPECT_GT(d.psnr_db, c.min_psnr) << c.plate;
        EXPECT_LT(d.psnr_db, 60) << c.plate << ": suspiciously exact";
    }
}

TEST_F(LatticeRender, CsgPrimitivesRasterizeToo) {
    // A primitive given as a CSG object (torus minus sphere), instanced twice.
    const Scene s = small("lattice-rings", 128);
    ASSERT_EQ(s.primitives.size(), 1u);
    const ImageDiffStats d = compare_images(render_exact(s), render_lattice(s, cache, 1));
    EXPECT_GT(d.psnr_db, 26);
    EXPECT_LT(d.psnr_db, 60);
}

TEST_F(LatticeRender, RefiningTheLatticeApproachesExact) {
    const Scene s = small("plate3-hair-closeup", 128);
    const Image8 exact = render_exact(s);
    const double p1 = compare_images(exact, render_lattice(s, cache, 1)).psnr_db;
    const double p2 = compare_images(exact, render_lattice(s, cache, 2)).psnr_db;
    const double p4 = compare_images(exact, render_lattice(s, cache, 4)).psnr_db;
    EXPECT_GT(p2, p1 + 1.0);
    EXPECT_GT(p4, p2 + 1.0);
}

TEST_F(LatticeRender, ThistlesShadowEachOtherOnlyInPlate2) {
    const Scene one = small("plate1-thistle-no-self-shading", 128);
    const Scene two = small("plate2-thistle", 128);
    const Image8 a = render_lattice(one, cache, 1), b = render_lattice(two, cache, 1);
    // Same geometry and lights; Plate 2 casts shadow rays, so some spikes are darker there and
    // none is brighter.
    int darker = 0, brighter = 0;
    for (std::size_t i = 0; i < a.rgb.size(); i += 3) {
        const int da = a.rgb[i] + a.rgb[i + 1] + a.rgb[i + 2], db = b.rgb[i] + b.rgb[i + 1] + b.rgb[i + 2];
        darker += db < da - 24;
        brighter += db > da;
    }
    EXPECT_GT(darker, 300);
    EXPECT_EQ(brighter, 0);
}

TEST_F(LatticeRender, NoSelfShadowAcne) {
    // Plate 3's hair shadows itself and the floor. Pixels that shadows darken in lattice mode
    // but not in exact mode are the lattice's own error; acne (a surface shadowing itself
    // through the table's inexactness) would add hundreds of them.
    Scene on = small("plate3-hair-closeup", 256);
    Scene off = on;
    off.shadows = false;
    const Image8 eo = render_exact(on), ef = render_exact(off);
    const Image8 lo = render_lattice(on, cache, 1), lf = render_lattice(off, cache, 1);
    auto sum = [](const Image8& img, std::size_t i) { return img.rgb[i] + img.rgb[i + 1] + img.rgb[i + 2]; };
    int exact_shadowed = 0, lattice_only = 0;
    for (std::size_t i = 0; i < eo.rgb.size(); i += 3) {
        exact_shadowed += sum(ef, i) > sum(eo, i) + 24;
        lattice_only += sum(lf, i) > sum(lo, i) + 24 && sum(ef, i) <= sum(eo, i) + 3;
    }
    EXPECT_GT(exact_shadowed, 300);
    EXPECT_LT(lattice_only, 300);  // measured: 103 (806 without the surface tolerance)
}

}  // namespace
}  // namespace lat
