#pragma once
// The scene behind a lattice.Scene.
#include "scene/scene.h"

namespace lat::py {

struct PyScene {
    Scene scene;
    double load_ms = 0;  // reading and checking it, for the render's stats
};

}  // namespace lat::py
