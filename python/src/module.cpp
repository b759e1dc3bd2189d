// The extension module meshcast._meshcast: the library's errors as Python
// exceptions, and the parts registered by their own files.
#include <pybind11/pybind11.h>

#include "meshcast/blob.h"
#include "meshcast/errors.h"
#include "python/src/blob_api.h"

namespace meshcast::python {
void register_scene(py::module_& m);
void register_raycasting_scene(py::module_& m);
}  // namespace meshcast::python

namespace py = pybind11;

PYBIND11_MODULE(_meshcast, m) {
  using namespace meshcast;
  // Bad input and calls the API does not allow are the caller's values;
  // a file that cannot be written is the system's; a GPU that fails is a
  // run-time condition.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const UsageError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const OutputError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const Error& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }
  });
  m.attr("__version__") = MESHCAST_VERSION;
  m.attr("NO_HIT") = kNoHit;
  py::dict features;
  features["vulkan"] = bool(MESHCAST_VULKAN);
  features["reader"] = bool(MESHCAST_READER);
  m.attr("features") = features;
  m.def("walker_isa", [] { return std::string(walker_isa_name(walker_isa())); },
        "The instruction set the CPU walkers run on (scalar, avx2 or avx512).");
  python::register_blob(m);
  python::register_scene(m);
  python::register_raycasting_scene(m);
}
