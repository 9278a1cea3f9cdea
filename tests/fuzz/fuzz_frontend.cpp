// libFuzzer target of the Mission Compiler front end: any byte sequence goes through
// lexer, parser, checker and — when it checks — the AMT, MEG and MDG builders. It must
// never crash, hang or exhaust memory; errors are the expected outcome for most inputs.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "graph/pipeline.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto source = std::make_shared<eamos::SourceFile>(
      "fuzz.eamos", std::string(reinterpret_cast<const char*>(data), size));
  eamos::Diagnostics diags;
  eamos::lang::CheckLimits limits;
  limits.max_expanded_nodes = 200000;  // keeps each run fast; the limit logic itself is exercised
  eamos::graph::Compilation c;
  eamos::graph::compile(source, eamos::fleet::Fleet{}, diags, c, limits);
  (void)diags.format();
  return 0;
}
