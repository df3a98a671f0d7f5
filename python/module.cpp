// The extension module pdflab._pdflab; the package pdflab (python/pdflab/)
// imports it and adds the Python side.
#include "python/bindings.h"

#include "renderer/error.h"

namespace py = pybind11;

PYBIND11_MODULE(_pdflab, m) {
  m.doc() = "pdflab's renderer library for Python (the package pdflab wraps it).";
  m.attr("__version__") = PDFLAB_VERSION;
  // Bad input is a ValueError carrying the command line's message; a failure
  // of the machine (a full disk) an OSError.
  static py::exception<pdflab::InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<pdflab::IoError> io_error(m, "IoError", PyExc_OSError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const pdflab::InputError& e) {
      input_error(e.what());
    } catch (const pdflab::IoError& e) {
      io_error(e.what());
    }
  });
  pdflab::python::bind_scene(m);
  pdflab::python::bind_render(m);
  pdflab::python::bind_measuring(m);
  pdflab::python::bind_sampling(m);
  py::module_ lab = m.def_submodule("lab");
  pdflab::python::bind_lab(lab);
}
