#pragma once
// The parts of the _caldaq module, each defined in its own file (module.cpp calls them).
#include <pybind11/pybind11.h>

namespace caldaq_py {
void bind_store(pybind11::module_& m);
void bind_analysis(pybind11::module_& m);
void bind_capture(pybind11::module_& m);
void bind_model(pybind11::module_& m);
}  // namespace caldaq_py
