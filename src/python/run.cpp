// Flying a compiled mission from Python: what `eamos run` does (src/cli/run.cpp), in this
// process, with every trace event handed to an optional Python callable as it happens.
#include <cmath>
#include <fstream>
#include <optional>
#include <stdexcept>

#include <pybind11/stl.h>

#include "bindings.h"
#include "deploy/mission_file.h"
#include "deploy/synthesize.h"
#include "dex/runner.h"
#include "dex/trace_writers.h"
#include "diag/number.h"
#include "mavlink_adapter/adapter.h"
#include "sim/sim_adapter.h"

namespace eamos::python {

namespace {

struct RunArgs {
  py::object on_event;
  double time_limit = 3600.0;
  double telemetry_hz = 5.0;
  std::optional<double> speed;  ///< none: virtual time
  std::optional<std::string> trace;
  bool tracks = true;  ///< keep every drone's whole track in the result
};

/// "KeyError: 'x'": the exception's type and words, without the traceback err.what() adds.
std::string exception_text(const py::error_already_set& err) {
  try {
    std::string text = py::str(err.type().attr("__name__"));
    std::string words = py::str(err.value());
    return words.empty() ? text : text + ": " + words;
  } catch (const std::exception&) {  // an exception whose str() raises
    PyErr_Clear();
    return "an exception";
  }
}

/// Gives each event to the callback as the trace line's dict. The run goes on without the
/// GIL; each event takes it. A callback that raises (or Ctrl-C, seen here as
/// KeyboardInterrupt) ends the mission as `eamos run` ends an interrupted one: every drone
/// runs its failsafe, and the exception is raised once the run has returned.
class PythonSink : public dex::TraceSink {
 public:
  PythonSink(py::object callback, const std::vector<std::string>& fleet, dex::RunInterrupt& interrupt)
      : callback_(std::move(callback)), fleet_(fleet), interrupt_(interrupt) {}

  void record(const dex::TraceEvent& e) override {
    if (error_ || failed_) return;
    py::gil_scoped_acquire gil;
    try {
      if (!callback_.is_none()) callback_(to_python(dex::trace_event_json(e, fleet_)));
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    } catch (py::error_already_set& err) {
      error_ = err;
      // Ctrl-C comes as KeyboardInterrupt, seen here or inside the callback.
      interrupt_.request(err.matches(PyExc_KeyboardInterrupt) ? std::string("interrupted (KeyboardInterrupt)")
                                                              : "the on_event callback raised " + exception_text(err));
    } catch (const std::exception& err) {
      failed_ = err.what();
      interrupt_.request(std::string("the on_event callback failed: ") + err.what());
    }
  }

  /// Without a callback it only watches for Ctrl-C: no message events need be built for it.
  bool takes_messages() const override { return !callback_.is_none(); }

  /// With the GIL held, after the run: raises what the callback raised, if anything.
  void rethrow() {
    if (error_) throw *error_;
    if (failed_) throw std::runtime_error(*failed_);
  }

 private:
  py::object callback_;
  const std::vector<std::string>& fleet_;
  dex::RunInterrupt& interrupt_;
  std::optional<py::error_already_set> error_;
  std::optional<std::string> failed_;
};

void check_args(const RunArgs& a) {
  if (!std::isfinite(a.time_limit) || a.time_limit <= 0)
    throw py::value_error("time_limit must be a positive number of mission seconds; give e.g. 3600");
  if (!std::isfinite(a.telemetry_hz) || a.telemetry_hz < 0)
    throw py::value_error("telemetry_hz must be 0 (no telemetry events) or a positive rate per mission second");
  if (a.speed && (!std::isfinite(*a.speed) || *a.speed <= 0))
    throw py::value_error("speed must be a positive factor of real time (1 = real time), or None for virtual time");
  if (!a.on_event.is_none() && !PyCallable_Check(a.on_event.ptr()))
    throw py::type_error("on_event must be a callable taking one event (a dict), or None");
}

std::vector<dex::Mission> load_missions(const graph::Compilation& c) {
  std::vector<dex::Mission> missions;
  std::vector<std::string> errors;
  if (!deploy::compiled_missions(c, missions, errors)) {
    std::string all;
    for (const std::string& e : errors) all += e + "\n";
    throw std::runtime_error(all);
  }
  return missions;
}

py::dict state_dict(const mid::DroneState& s) {
  py::dict out;
  out["x"] = s.x;
  out["y"] = s.y;
  out["z"] = s.z;
  out["heading"] = std::isfinite(s.heading) ? py::object(py::float_(s.heading)) : py::object(py::none());
  out["armed"] = s.armed;
  out["landed"] = s.landed;
  out["battery"] = s.battery;
  out["pictures"] = s.pictures;
  out["mode"] = utf8(s.mode);
  return out;
}

/// The track as columns (t, x, y, z, armed, landed, battery): ready for plotting.
py::dict track_dict(const std::vector<dex::Sample>& track) {
  py::list t, x, y, z, armed, landed, battery;
  for (const dex::Sample& s : track) {
    t.append(s.t);
    x.append(s.x);
    y.append(s.y);
    z.append(s.z);
    armed.append(s.armed);
    landed.append(s.landed);
    battery.append(s.battery);
  }
  py::dict out;
  out["t"] = t;
  out["x"] = x;
  out["y"] = y;
  out["z"] = z;
  out["armed"] = armed;
  out["landed"] = landed;
  out["battery"] = battery;
  return out;
}

py::dict result_dict(const dex::RunResult& r) {
  py::dict out;
  out["completed"] = r.completed;
  out["duration"] = r.duration;
  out["error"] = utf8(r.error);
  out["activations"] = r.activations;
  out["max_lag"] = r.max_lag;
  py::object failure = py::none();
  if (r.failure) {
    py::dict f;
    f["drone"] = r.failure->drone;
    f["action"] = r.failure->action;
    f["line"] = r.failure->line;
    f["reason"] = utf8(r.failure->reason);
    f["kind"] = r.failure->kind == mid::FailureReason::none ? py::object(py::none())
                                                            : py::object(py::str(mid::failure_reason_name(r.failure->kind)));
    f["detail"] = utf8(r.failure->detail);
    failure = f;
  }
  out["failure"] = failure;
  py::list drones;
  for (const dex::DroneSummary& d : r.drones) {
    py::dict s;
    s["name"] = d.name;
    s["final"] = d.final;
    s["state"] = state_dict(d.state);
    s["track"] = track_dict(d.track);
    drones.append(s);
  }
  out["drones"] = drones;
  return out;
}

py::dict run(const CompiledMission& m, const RunArgs& a) {
  if (!m.ok) throw std::runtime_error("the mission did not compile: " + m.diags.format());
  check_args(a);
  const graph::Compilation& c = m.c;
  std::vector<dex::Mission> missions = load_missions(c);
  const std::string hash = missions.front().hash;  // deploy::mission_hash(c), as every file carries it
  // The output is checked before anything flies.
  std::ofstream trace_file;
  if (a.trace) {
    trace_file.open(*a.trace, std::ios::trunc);
    if (!trace_file) throw py::value_error("cannot write trace '" + *a.trace + "'; check the path and permissions");
  }
  mid::AdapterRegistry adapters;
  sim::register_adapter(adapters);
  mavlink_adapter::register_adapter(adapters, {.real_time = a.speed.has_value(), .speed = a.speed.value_or(1.0)});

  dex::RunInterrupt interrupt;
  PythonSink sink(a.on_event, missions[0].fleet, interrupt);
  dex::TeeTrace tee;
  std::unique_ptr<dex::JsonlTrace> jsonl;
  if (a.trace) {
    jsonl = std::make_unique<dex::JsonlTrace>(trace_file, missions[0].fleet);
    jsonl->write_header(deploy::trace_header(c, hash, a.telemetry_hz));
    tee.add(jsonl.get());
  }
  tee.add(&sink);
  dex::RunOptions options;
  options.time_limit_s = a.time_limit;
  options.interrupt = &interrupt;
  options.telemetry_hz = a.telemetry_hz;
  options.keep_tracks = a.tracks;
  if (a.speed) {
    options.clock.mode = mid::ClockMode::real_time;
    options.clock.speed = *a.speed;
  }
  dex::RunResult result;
  {
    py::gil_scoped_release release;
    result = dex::run_in_process(missions, adapters, &tee, options);
  }
  if (trace_file.is_open()) {
    trace_file.close();
    if (!trace_file) throw py::value_error("could not finish writing trace '" + *a.trace + "' (disk full?)");
  }
  sink.rethrow();
  py::dict out = result_dict(result);
  py::list warnings;
  for (const std::string& w : dex::run_warnings(result, "speed=" + diag::number_text(a.speed.value_or(1.0))))
    warnings.append(utf8(w));
  out["warnings"] = warnings;
  return out;
}

}  // namespace

void bind_run(py::module_& m) {
  m.def(
      "run",
      [](const CompiledMission& c, py::object on_event, double time_limit, double telemetry_hz,
         std::optional<double> speed, std::optional<std::string> trace, bool tracks) {
        return run(c, {std::move(on_event), time_limit, telemetry_hz, speed, std::move(trace), tracks});
      },
      py::arg("mission"), py::arg("on_event") = py::none(), py::arg("time_limit") = 3600.0,
      py::arg("telemetry_hz") = 5.0, py::arg("speed") = py::none(), py::arg("trace") = py::none(),
      py::arg("tracks") = true);
}

}  // namespace eamos::python
