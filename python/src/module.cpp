// _caldaq: the C++ half of `import caldaq` (docs/python.md). The library's errors become Python
// exceptions carrying the message the CLI prints after "daq: error: ".
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "cal/analysis/error.hpp"
#include "cal/replay/capture.hpp"
#include "cal/storage/store.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_caldaq, m) {
  m.doc() = "caldaq's store, analysis library and captures (docs/python.md)";
  // Each is a subclass of caldaq.Error, so one except clause takes any of them; InputError is
  // also a ValueError (bad input) and the others OSErrors (a file that cannot be used).
  static py::exception<std::runtime_error> error(m, "Error", PyExc_Exception);
  static py::exception<cal::InputError> input_error(
      m, "InputError", py::make_tuple(error, py::handle(PyExc_ValueError)).ptr());
  static py::exception<cal::storage::StoreError> store_error(
      m, "StoreError", py::make_tuple(error, py::handle(PyExc_OSError)).ptr());
  static py::exception<cal::replay::CaptureError> capture_error(
      m, "CaptureError", py::make_tuple(error, py::handle(PyExc_OSError)).ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const cal::InputError& e) {
      PyErr_SetString(input_error.ptr(), e.what());
    } catch (const cal::storage::StoreError& e) {
      PyErr_SetString(store_error.ptr(), e.what());
    } catch (const cal::replay::CaptureError& e) {
      PyErr_SetString(capture_error.ptr(), e.what());
    }
  });
  caldaq_py::bind_store(m);
  caldaq_py::bind_analysis(m);
  caldaq_py::bind_capture(m);
  caldaq_py::bind_model(m);
}
