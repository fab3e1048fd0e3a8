// Scene files: JSON text -> Scene (load_scene_text), then a few rays through each object's
// shape. Every input must load or throw InputError; anything else (a crash, a sanitizer report,
// another exception) is a finding.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_rays.h"
#include "scene/scene_loader.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const lat::Scene scene = lat::load_scene_text(text, "fuzz.json");
        // 16: enough to reach every kind of shape; keeps runs fast
        for (std::size_t i = 0; i < std::min<std::size_t>(scene.object_count(), 16); ++i) {
            const lat::SceneObject o = scene.object(i);
            lat::fuzz::trace_a_few_rays(*o.shape, o.xf);
        }
    } catch (const lat::InputError&) {
    }
    return 0;
}
