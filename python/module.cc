// exotwin._exotwin: the extension module's entry point and the project's exceptions (see module.h).
#include "core/error.h"
#include "python/module.h"

PYBIND11_MODULE(_exotwin, m) {
  namespace py = pybind11;
  m.doc() = "exotwin's C++ layers (the public API is the package exotwin)";
  // InputError: bad input, the CLI's exit 2 with the same text; SimulationError: divergence (exit 1).
  py::register_exception<exotwin::InputError>(m, "InputError", PyExc_ValueError);
  py::register_exception<exotwin::SimulationError>(m, "SimulationError", PyExc_RuntimeError);
  exotwin::python::BindRun(m);
  exotwin::python::BindTwin(m);
  exotwin::python::BindCommands(m);
  exotwin::python::BindRender(m);
}
