// eamos._core: the compiler, the in-process runner and the trace reader for Python. The
// package eamos (src/python/eamos) is the interface users import; this is its engine.
#include "bindings.h"
#include "version.h"

PYBIND11_MODULE(_core, m) {
  m.doc() = "eamos's compiler, simulator runs and trace reader; import eamos, not this module";
  m.attr("__version__") = EAMOS_VERSION;
  eamos::python::bind_compile(m);
  eamos::python::bind_run(m);
  eamos::python::bind_trace(m);
}
