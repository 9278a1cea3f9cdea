// A trace file as `eamos monitor` and the trace-schema check (the tests, the Python module)
// read it: every line checked, what reaches a page re-serialised from the checked values.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "monitor/trace_file.h"
#include "trace/trace_schema.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::istringstream for_monitor(text);
  eamos::monitor::LoadedTrace loaded = eamos::monitor::read_trace("fuzz.jsonl", for_monitor);
  if (loaded.header) (void)loaded.header->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::istringstream for_check(text);
  (void)eamos::trace::check_trace(for_check);
  return 0;
}
