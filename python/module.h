// The Python extension module exotwin._exotwin (pybind11): the C++ layers bound for the package
// python/exotwin/, which is the public form (DESIGN.md "Python module"). Each module_*.cc binds one
// concern; this header holds what they share. No physics, parsing or selection here: the bindings
// call the layers and convert their results.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "runner/runner.h"

namespace exotwin::python {

namespace py = pybind11;

// While alive, SIGINT and SIGTERM set the stop request (core/stop_signal.h) that ends a run at a step's
// end, as in `exotwin run`; the interpreter's handlers come back when the last scope of the process
// ends (scopes on several threads share one installation).
class StopSignalScope {
 public:
  StopSignalScope();
  ~StopSignalScope();
  StopSignalScope(const StopSignalScope&) = delete;
  StopSignalScope& operator=(const StopSignalScope&) = delete;
};

// A (rows, columns) float64 array over `values` (row-major), which it takes: one buffer, owned by a
// capsule, no copy.
py::array RowsArray(std::vector<double>&& values, size_t columns);

// column name -> the column of `rows` (a view, no copy).
py::dict ColumnsOf(const py::array& rows, const std::vector<std::string>& columns);

// A run's result as a dict: scenario, seed, metrics, checks, events, files, interrupted (None or
// {signal, name, t_s, trial}) and logs ({file name: {column: array}}, taken from `logs`, may be null).
py::dict ResultDict(RunResult& r, LogCapture* logs);

void BindRun(py::module_& m);
void BindTwin(py::module_& m);
void BindCommands(py::module_& m);
void BindRender(py::module_& m);

}  // namespace exotwin::python
