// Compiling a mission from Python: the same pipeline as `eamos check` and `eamos compile`,
// its diagnostics as data, and the graphs through the JSON exporters `eamos graph` uses.
#include <optional>
#include <stdexcept>

#include <pybind11/stl.h>

#include "bindings.h"
#include "deploy/mission_file.h"
#include "fleet/fleet.h"
#include "graph/export.h"

namespace eamos::python {

namespace {

py::dict diagnostic_dict(const Diagnostic& d) {
  // The text of this diagnostic alone, as `eamos check` prints it (location, source line, caret).
  Diagnostics one;
  one.max_errors = 0;
  one.add(d);
  py::dict out;
  out["file"] = d.has_file ? py::object(utf8(d.path)) : py::object(py::none());
  out["line"] = d.loc.line;
  out["column"] = d.loc.col;
  out["severity"] = severity_name(d.severity);
  out["message"] = utf8(d.message);
  out["text"] = utf8(one.format());
  return out;
}

std::shared_ptr<CompiledMission> compile_file(const std::string& path, const std::optional<std::string>& fleet) {
  auto m = std::make_shared<CompiledMission>();
  m->ok = graph::compile_file(path, fleet.value_or(""), m->diags, m->c) && !m->diags.has_errors();
  return m;
}

std::shared_ptr<CompiledMission> compile_text(const std::string& text, const std::string& name,
                                              const std::optional<std::string>& fleet_path,
                                              const std::optional<std::string>& fleet_text) {
  auto m = std::make_shared<CompiledMission>();
  // As compile_file: a fleet with errors still yields what parsed, and the mission is checked
  // against it, so one call lists the errors of both.
  fleet::Fleet fleet;
  if (fleet_path) fleet::load_fleet(*fleet_path, fleet, m->diags);
  else if (fleet_text) fleet::parse_fleet(std::make_shared<SourceFile>("<fleet>", *fleet_text), fleet, m->diags);
  bool fleet_ok = !m->diags.has_errors();
  m->ok = graph::compile(std::make_shared<SourceFile>(name, text), fleet, m->diags, m->c) && fleet_ok &&
          !m->diags.has_errors();
  return m;
}

const CompiledMission& compiled(const CompiledMission& m) {
  if (!m.ok) throw std::runtime_error("the mission did not compile: " + m.diags.format());
  return m;
}

int drone_index(const CompiledMission& m, int drone) {
  if (drone < 0 || drone >= m.c.drone_count())
    throw py::index_error("drone index " + std::to_string(drone) + " is out of range: the mission has " +
                          std::to_string(m.c.drone_count()) + " drones");
  return drone;
}

py::list diagnostics(const CompiledMission& m) {
  py::list out;
  for (const Diagnostic& d : m.diags.items()) out.append(diagnostic_dict(d));
  return out;
}

py::list drones(const CompiledMission& m) {
  py::list out;
  for (int d = 0; d < compiled(m).c.drone_count(); ++d) out.append(m.c.drone_name(d));
  return out;
}

py::object mission_file(const CompiledMission& m, int drone) {
  const graph::Compilation& c = compiled(m).c;
  std::string text = deploy::mission_text(c, drone_index(m, drone), deploy::mission_hash(c));
  return to_python(nlohmann::json::parse(text));
}

}  // namespace

void bind_compile(py::module_& m) {
  py::class_<CompiledMission, std::shared_ptr<CompiledMission>>(m, "CompiledMission",
                                                                 "One compile's diagnostics and graphs.")
      .def_property_readonly("ok", [](const CompiledMission& c) { return c.ok; })
      .def_property_readonly("error_count", [](const CompiledMission& c) { return c.diags.error_count(); })
      .def_property_readonly("warning_count", [](const CompiledMission& c) { return c.diags.warning_count(); })
      .def("diagnostics", &diagnostics)
      .def("formatted", [](const CompiledMission& c) { return utf8(c.diags.format()); })
      .def("drones", &drones)
      .def("amt", [](const CompiledMission& c) { return to_python(graph::amt_json(compiled(c).c)); })
      .def("meg", [](const CompiledMission& c) { return to_python(graph::meg_json(compiled(c).c)); })
      .def("mdg", [](const CompiledMission& c, int d) { return to_python(graph::mdg_json(compiled(c).c, drone_index(c, d))); })
      .def("stats", [](const CompiledMission& c) { return to_python(graph::stats_json(compiled(c).c)); })
      .def("mission_file", &mission_file);
  m.def("compile_file", &compile_file, py::arg("path"), py::arg("fleet") = py::none(),
        py::call_guard<py::gil_scoped_release>());
  m.def("compile_text", &compile_text, py::arg("text"), py::arg("name"), py::arg("fleet") = py::none(),
        py::arg("fleet_text") = py::none(), py::call_guard<py::gil_scoped_release>());
}

}  // namespace eamos::python
