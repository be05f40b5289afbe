// exotwin.run and what it shares with the other bindings: the exceptions, logs as NumPy arrays, the
// stop-signal scope (see python/module.h).
#include <csignal>
#include <mutex>

#include "core/error.h"
#include "core/stop_signal.h"
#include "python/module.h"
#include "runner/out_folder_lock.h"
#include "runner/runner.h"
#include "runner/scenario.h"

namespace exotwin::python {

namespace {

// The process's stop-signal scopes: the first installs the run's handlers (InstallStopSignalHandlers)
// over the interpreter's, the last puts the interpreter's back.
std::mutex g_stop_mutex;
int g_stop_scopes = 0;
struct sigaction g_saved_int, g_saved_term;

}  // namespace

StopSignalScope::StopSignalScope() {
  std::lock_guard<std::mutex> lock(g_stop_mutex);
  if (g_stop_scopes++ > 0) return;
  sigaction(SIGINT, nullptr, &g_saved_int);
  sigaction(SIGTERM, nullptr, &g_saved_term);
  ResetStopSignal();
  InstallStopSignalHandlers();
}

StopSignalScope::~StopSignalScope() {
  std::lock_guard<std::mutex> lock(g_stop_mutex);
  if (--g_stop_scopes > 0) return;
  sigaction(SIGINT, &g_saved_int, nullptr);
  sigaction(SIGTERM, &g_saved_term, nullptr);
  ResetStopSignal();  // a stop request ends the runs it reached, not the twins and runs after them
}

py::array RowsArray(std::vector<double>&& values, size_t columns) {
  auto* owned = new std::vector<double>(std::move(values));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  const size_t rows = columns ? owned->size() / columns : 0;
  return py::array_t<double>({rows, columns}, {columns * sizeof(double), sizeof(double)}, owned->data(), owner);
}

py::dict ColumnsOf(const py::array& rows, const std::vector<std::string>& columns) {
  py::dict out;
  for (size_t c = 0; c < columns.size(); ++c)
    out[py::str(columns[c])] = rows[py::make_tuple(py::slice(py::none(), py::none(), py::none()), py::int_(c))];
  return out;
}

py::dict ResultDict(RunResult& r, LogCapture* logs) {
  py::dict d;
  d["scenario"] = r.scenario;
  d["seed"] = r.seed;
  py::dict metrics;
  for (const auto& kv : r.metrics) metrics[py::str(kv.first)] = kv.second;
  d["metrics"] = metrics;
  py::list checks;
  for (const CheckResult& c : r.checks) {
    py::dict cd;
    cd["name"] = c.name;
    cd["metric"] = c.metric;
    cd["op"] = c.op;
    cd["passed"] = c.passed;
    cd["value"] = c.value;
    cd["limit"] = c.limit;
    checks.append(cd);
  }
  d["checks"] = checks;
  d["events"] = r.events;
  d["files"] = r.files;
  if (r.interrupted) {
    py::dict i;
    i["signal"] = r.interrupted->signal;
    i["name"] = StopSignalName(r.interrupted->signal);
    i["t_s"] = r.interrupted->t;
    i["trial"] = r.interrupted->trial;
    d["interrupted"] = i;
  } else {
    d["interrupted"] = py::none();
  }
  py::dict files;
  if (logs)
    for (CapturedLog& log : *logs) {
      const size_t columns = log.columns.size();
      files[py::str(log.file)] = ColumnsOf(RowsArray(std::move(log.values), columns), log.columns);
    }
  d["logs"] = files;
  return d;
}

namespace {

// exotwin._run(scenario, seed, out, mcap): RunScenario on the scenario file with the logs kept in memory, the
// interpreter's lock released and SIGINT / SIGTERM ending the run as in the CLI (the Python package
// raises KeyboardInterrupt with the partial result, python/exotwin/__init__.py).
py::dict Run(const std::string& scenario, std::optional<uint64_t> seed, const std::string& out, const std::string& mcap) {
  RunResult r;
  LogCapture logs;
  {
    py::gil_scoped_release release;
    const Scenario s = ReadScenario(scenario);
    const OutFolderLock lock(out);
    RunOptions opt;
    opt.out_dir = out;
    opt.seed = seed;
    opt.mcap = mcap;
    opt.capture = &logs;
    const StopSignalScope stop;
    r = RunScenario(s, opt);
  }
  return ResultDict(r, &logs);
}

}  // namespace

void BindRun(py::module_& m) {
  m.def("_run", &Run, py::arg("scenario"), py::arg("seed"), py::arg("out"), py::arg("mcap") = "",
        "RunScenario on a scenario file (exotwin.run is the public form)");
}

}  // namespace exotwin::python
