#pragma once
// The pieces of the Python module `lattice` (module.cpp): each binds one part of the library.
#include <mutex>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "io/image.h"
#include "render/core/renderer.h"

namespace lat::py {

namespace pyb = pybind11;

void bind_images(pyb::module_& m);  // to_srgb8, compare
void bind_scene(pyb::module_& m);   // Scene, load, scatters
void bind_render(pyb::module_& m);  // render, render_options
void bind_tables(pyb::module_& m);  // rasterize, open_table, Table

// Held (without the GIL) by whatever sets the thread limit, signal handlers or progress sink,
// which belong to the process: renders, rasterizations and certifications run one at a time.
std::mutex& process_mutex();

// A render's image as numpy sees it: an H x W x 3 float32 array of linear radiance whose memory
// is this holder, which also keeps the command line's 8-bit image of the same render (the mean of
// clamped samples, which the radiance alone does not give when spp > 1), so that to_srgb8 of the
// array, unmodified, is exactly the PNG's pixels.
struct RenderedImage {
    ImageF radiance;
    Image8 display;
    std::uint64_t radiance_hash = 0;
};
pyb::array_t<float> radiance_array(RenderOutput&& out);

// An H x W x 3 uint8 array holding a copy of img.
pyb::array_t<std::uint8_t> image8_array(const Image8& img);

}  // namespace lat::py
