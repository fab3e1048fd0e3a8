// The Python module `lattice` (docs/python.md): scenes, renders, tables and comparisons, with
// numpy arrays in and out, through the same code as the command line.
#include <pybind11/pybind11.h>

#include "bindings.h"
#include "util/error.h"
#include "util/interrupt.h"

PYBIND11_MODULE(lattice, m) {
    namespace pyb = pybind11;
    m.doc() = "Ray tracing objects with fine surface detail through lattices (docs/python.md)";
    // A user's mistake (bad scene, missing or corrupt file, impossible size), its message naming
    // the file and the place, as the command line prints it. A ValueError.
    static pyb::exception<lat::InputError> input_error(m, "InputError", PyExc_ValueError);
    pyb::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const lat::InputError& e) {
            input_error(e.what());
        } catch (const lat::Interrupted& e) {
            PyErr_SetString(e.signal() == 2 ? PyExc_KeyboardInterrupt : PyExc_SystemExit, e.what());
        }
    });
    lat::py::bind_images(m);
    lat::py::bind_scene(m);
    lat::py::bind_render(m);
    lat::py::bind_tables(m);
}
