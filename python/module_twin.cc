// exotwin.Twin: the EXOwheel twin stepped one controller period at a time (runner/exowheel_runner.h
// ExowheelSession), the control law's output given from Python or the shipped controller's own.
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>

#include "core/error.h"
#include "python/module.h"
#include "runner/exowheel_runner.h"
#include "runner/scenario.h"

namespace exotwin::python {
namespace {

// MuJoCo's model loading and the other set-up are not known to be thread-safe: one twin is set up at a
// time in the process; their steps run in parallel (each twin owns its plant, bus and controller).
std::mutex g_setup_mutex;

class Twin {
 public:
  // `out`: the folder of result.json (and of the logs when `logs`); it exists and outlives the twin.
  Twin(const std::string& scenario, std::optional<uint64_t> seed, const std::string& out, bool logs) {
    {
      py::gil_scoped_release release;
      s_ = ReadScenario(scenario);
    }
    if (s_.device == Device::kHal3 || s_.emg_calibration)
      throw InputError(s_.source + ": exotwin.Twin steps the EXOwheel closed loop (device exowheel or "
                       "exowheel_exo_only, no emg_calibration block); got device " + DeviceName(s_.device) +
                       (s_.emg_calibration ? " with an emg_calibration block" : "") + " (exotwin.run runs it)");
    if (!logs) s_.log_measured_csv = false;
    opt_.out_dir = out;
    seed_ = seed ? *seed : s_.seed;
    Reset(std::nullopt);
  }

  py::dict Reset(std::optional<uint64_t> seed) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (seed) seed_ = *seed;
    opt_.seed = seed_;
    {
      py::gil_scoped_release release;
      session_.reset();  // its logs closed before the new session opens them again
      std::lock_guard<std::mutex> setup(g_setup_mutex);
      session_ = std::make_unique<ExowheelSession>(s_, opt_);
    }
    result_ = py::none();
    failed_.clear();
    if (keys_.empty()) {
      for (const std::string& c : session_->MeasuredColumns()) keys_.push_back(py::str(c));
      for (const std::string& c : session_->TruthColumns()) truth_keys_.push_back(py::str(c));
    }
    Capture();
    return Observation();
  }

  py::dict Step(const py::handle& command) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!failed_.empty()) throw std::runtime_error("Twin.step: " + failed_ + "; reset() starts the run again");
    if (session_->done())
      throw std::runtime_error("Twin.step: the run is over (t = " + std::to_string(session_->time()) +
                               " s, trial " + std::to_string(session_->trial() + 1) + " of " +
                               std::to_string(s_.protocol.trials) + "); reset() starts it again");
    double cmd[2];
    const double* given = command.is_none() ? nullptr : Command(command, cmd);
    try {
      py::gil_scoped_release release;
      session_->Advance(session_->steps_per_tick(), given);
    } catch (const std::exception& e) {
      failed_ = e.what();
      throw;
    }
    Capture();
    if (session_->done()) Finish();
    return Observation();
  }

  py::dict Truth() const {
    py::dict d;
    for (size_t i = 0; i < truth_keys_.size(); ++i) d[truth_keys_[i]] = truth_[i];
    return d;
  }

  bool done() const { return session_->done(); }
  double time() const { return measured_.empty() ? 0.0 : measured_[0]; }
  int trial() const { return session_->trial(); }
  double period() const { return 1.0 / s_.controller.rate_hz; }
  double duration() const { return s_.protocol.duration; }
  int trials() const { return s_.protocol.trials; }
  double command_limit() const { return s_.controller.torque_limit; }  // N m, the supervisor's limit
  int safety_state() const { return session_->safety_state(); }
  std::vector<std::string> observation_columns() const {
    std::vector<std::string> c;
    for (const py::str& k : keys_) c.push_back(k);
    return c;
  }
  py::object result() const { return result_; }

 private:
  // The command's two values (N m, hip then knee) into cmd; TypeError / InputError on a wrong one.
  // Fast paths (no array made): a float64 array of shape (2,), a tuple or list of two Python floats.
  const double* Command(const py::handle& command, double* cmd) const {
    bool read = false;
    if (py::array_t<double>::check_(command)) {  // float64 in the machine's byte order
      const auto a = py::reinterpret_borrow<py::array>(command);
      if (a.ndim() == 1 && a.shape(0) == 2) {
        const char* p = static_cast<const char*>(a.data());
        cmd[0] = *reinterpret_cast<const double*>(p);
        cmd[1] = *reinterpret_cast<const double*>(p + a.strides(0));
        read = true;
      }
    } else if ((PyTuple_Check(command.ptr()) || PyList_Check(command.ptr())) && PySequence_Fast_GET_SIZE(command.ptr()) == 2) {
      PyObject* x = PySequence_Fast_GET_ITEM(command.ptr(), 0);
      PyObject* y = PySequence_Fast_GET_ITEM(command.ptr(), 1);
      if (PyFloat_CheckExact(x) && PyFloat_CheckExact(y)) {
        cmd[0] = PyFloat_AS_DOUBLE(x);
        cmd[1] = PyFloat_AS_DOUBLE(y);
        read = true;
      }
    }
    if (read) return Finite(cmd);
    py::array a = py::array::ensure(command);
    if (!a) throw py::type_error("Twin.step: command: expected a numpy array of 2 torques (cmd_hip, cmd_knee, N m) or None");
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u')
      throw py::type_error("Twin.step: command: expected a real (float or integer) array of 2 torques "
                           "(cmd_hip, cmd_knee, N m), got dtype " + std::string(py::str(a.dtype())));
    if (a.ndim() != 1 || a.shape(0) != 2) {
      std::string shape = "(";
      for (py::ssize_t i = 0; i < a.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(a.shape(i));
      throw InputError("Twin.step: command: expected shape (2,) (cmd_hip, cmd_knee, N m), got shape " + shape +
                       (a.ndim() == 1 ? ",)" : ")"));
    }
    const auto d = py::array_t<double, py::array::forcecast>::ensure(a);
    for (int j = 0; j < 2; ++j) cmd[j] = d.at(j);
    return Finite(cmd);
  }

  static const double* Finite(const double* cmd) {
    static const char* kJoint[2] = {"cmd_hip", "cmd_knee"};
    for (int j = 0; j < 2; ++j)
      if (!std::isfinite(cmd[j]))
        throw InputError("Twin.step: command: " + std::string(kJoint[j]) + " is " + std::to_string(cmd[j]) +
                         ", expected a finite torque (N m)");
    return cmd;
  }

  void Capture() {
    measured_.resize(keys_.size());
    truth_.resize(truth_keys_.size());
    session_->MeasuredRow(measured_.data());
    session_->TruthRow(truth_.data());
  }

  py::dict Observation() const {
    py::dict d;
    for (size_t i = 0; i < keys_.size(); ++i) d[keys_[i]] = measured_[i];
    return d;
  }

  void Finish() {
    RunResult r;
    {
      py::gil_scoped_release release;
      r = session_->Finish();
    }
    result_ = ResultDict(r, nullptr);
  }

  Scenario s_;
  RunOptions opt_;
  uint64_t seed_ = 0;
  std::unique_ptr<ExowheelSession> session_;
  std::vector<py::str> keys_, truth_keys_;
  std::vector<double> measured_, truth_;
  py::object result_ = py::none();
  std::string failed_;  // the error that ended the session early
  std::mutex mutex_;    // one call at a time on a twin shared by threads
};

}  // namespace

void BindTwin(py::module_& m) {
  py::class_<Twin>(m, "_Twin")
      .def(py::init<const std::string&, std::optional<uint64_t>, const std::string&, bool>(), py::arg("scenario"),
           py::arg("seed"), py::arg("out"), py::arg("logs"))
      .def("reset", &Twin::Reset, py::arg("seed") = py::none())
      .def("step", &Twin::Step, py::arg("command") = py::none())
      .def("truth", &Twin::Truth)
      .def_property_readonly("done", &Twin::done)
      .def_property_readonly("time", &Twin::time)
      .def_property_readonly("trial", &Twin::trial)
      .def_property_readonly("period", &Twin::period)
      .def_property_readonly("duration", &Twin::duration)
      .def_property_readonly("trials", &Twin::trials)
      .def_property_readonly("command_limit", &Twin::command_limit)
      .def_property_readonly("safety_state", &Twin::safety_state)
      .def_property_readonly("observation_columns", &Twin::observation_columns)
      .def_property_readonly("result", &Twin::result);
}

}  // namespace exotwin::python
