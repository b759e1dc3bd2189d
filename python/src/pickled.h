// The parts of a pickled state (a Scene's, a RaycastingScene's) read back
// with their types checked: a damaged or altered pickle is answered with a
// TypeError naming the part, the type expected and the type found, where
// pybind11's own cast error names neither (and its tuple and list would
// take any iterable, a string's characters included).
#pragma once
#include <pybind11/pybind11.h>

#include <string>
#include <type_traits>

namespace meshcast::python {

namespace py = pybind11;

inline py::type_error pickled_error(const py::handle& part, const std::string& what, const char* expected) {
  std::string found = Py_TYPE(part.ptr())->tp_name;
  const std::string repr = py::repr(part);
  if (repr.size() <= 40) found += " " + repr;  // a number, None, a short string: shown
  return py::type_error(what + ": " + expected + " expected, " + found + " found");
}

// `part` as a T: a Python type (py::tuple, py::bytes) only where it is one,
// a C++ value where pybind11 converts it; `expected` says what T is.
template <class T>
T pickled(const py::handle& part, const std::string& what, const char* expected) {
  if constexpr (std::is_base_of_v<py::object, T>) {
    if (!py::isinstance<T>(part)) throw pickled_error(part, what, expected);
    return py::reinterpret_borrow<T>(part);
  } else {
    try {
      return part.cast<T>();
    } catch (const py::cast_error&) {
      throw pickled_error(part, what, expected);
    }
  }
}

}  // namespace meshcast::python
