// `eamos verify`: compile, read back every drone's mission file as `eamos run` does, and
// let src/verify fly every explored path in the simulator and check it.
#include <iostream>

#include "cli/commands.h"
#include "deploy/mission_file.h"
#include "verify/verify.h"

namespace eamos::cli {

int cmd_verify(const CommonOptions& o, const VerifyCommandOptions& v) {
  graph::Compilation c;
  if (!compile_and_report(o, c)) return 1;
  std::vector<dex::Mission> missions;
  if (!load_compiled_missions(c, missions)) return 1;
  verify::VerifyOptions options;
  options.max_paths = v.paths;
  options.jitter = v.jitter;
  options.time_limit_s = v.time_limit;
  verify::VerifyReport report = verify::verify(c, missions, options);
  if (!v.plot.empty() && !write_output(v.plot, verify::plot_worst_path(c, missions, options, report))) return 1;
  std::cerr.flush();
  std::cout << (v.json ? verify::json_report(c, report) : verify::format_report(c, report));
  std::cout.flush();
  return report.error.empty() && report.violations.empty() ? 0 : 1;
}

}  // namespace eamos::cli
