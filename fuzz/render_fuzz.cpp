// Scene files rendered: JSON text -> Scene -> TracedScene (Embree) -> a 4 x 3 image with one
// light sample per pixel. The path of an old SIGABRT (a non-finite ray handed to
// Embree), so it goes through the renderer as `lattice render` does. Slower than the `scene`
// harness (an Embree device per input), so it stops at small scenes.
#include <cstddef>
#include <cstdint>
#include <string>

#include "render/modes/integrators.h"
#include "scene/scene_loader.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        lat::Scene scene = lat::load_scene_text(text, "fuzz.json");
        if (scene.object_count() > 32) return 0;
        scene.camera.width = 4;  // the geometry is what is fuzzed, not the image size
        scene.camera.height = 3;
        const lat::TracedScene rs(scene);
        (void)lat::render_exact(rs, {});
    } catch (const lat::InputError&) {
    }
    return 0;
}
