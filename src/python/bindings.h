#pragma once
// The pieces of the Python module eamos._core, each bound by its own file; module.cpp puts
// them together. Everything crosses into Python as plain data (dict, list, str, numbers):
// the pure-Python package (eamos/__init__.py) wraps it in classes.
#include <memory>
#include <string>

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>

#include "diag/diagnostics.h"
#include "graph/pipeline.h"

namespace eamos::python {

namespace py = pybind11;

/// Text from outside (a mission file, a trace, a vehicle's words) may hold bytes that are not
/// UTF-8: they become U+FFFD, as the trace writer does, instead of a UnicodeDecodeError.
py::str utf8(const std::string& s);

/// JSON as Python data: objects become dicts (in the JSON's order), arrays lists.
py::object to_python(const nlohmann::json& j);
py::object to_python(const nlohmann::ordered_json& j);

/// One compile: its diagnostics and, when it succeeded, every graph. Held by a shared
/// pointer and never moved: the graphs point into the compilation's own members.
struct CompiledMission {
  Diagnostics diags;
  graph::Compilation c;
  bool ok = false;
};

void bind_compile(py::module_& m);
void bind_run(py::module_& m);
void bind_trace(py::module_& m);

}  // namespace eamos::python
