#include "graph/pipeline.h"

#include "graph/static_checks.h"
#include "lang/parser.h"

namespace eamos::graph {

namespace {

/// Once the MEG exists, the logic checks read of the statements only the control
/// structures (a finding names their branch blocks). The others, a fifth of a large
/// mission's memory, are freed before the checks' working sets are made. The MEG's
/// arguments and conditions point into Mission::expressions, which stays.
void keep_control_statements(Compilation& c) {
  for (lang::Function& f : c.mission.functions) {
    std::vector<lang::Statement> controls;
    for (lang::Statement& s : f.body)
      if (s.control != lang::ControlKind::none) controls.push_back(std::move(s));
    f.body.swap(controls);
  }
}

/// After the last check, a deployment needs no statement.
void drop_statements(Compilation& c) {
  for (lang::Function& f : c.mission.functions) std::vector<lang::Statement>().swap(f.body);
}

}  // namespace

bool compile(std::shared_ptr<SourceFile> source, const fleet::Fleet& fleet, Diagnostics& diags,
             Compilation& out, const lang::CheckLimits& limits, Keep keep) {
  out.source = std::move(source);
  out.fleet = fleet;
  out.mission = lang::parse_mission(*out.source, diags);
  out.checked = lang::check_mission(out.mission, out.fleet, diags, limits);
  if (diags.has_errors()) return false;
  for (int d = 0; d < out.drone_count(); ++d)
    out.settings.push_back(out.fleet.settings_for(out.mission.drones[d].name,
                                                  out.mission.drones[d].type, d));
  out.meg = build_meg(out.mission);
  if (keep == Keep::all_graphs) out.amt = build_amt(out.mission);
  if (keep == Keep::deployment_graphs) keep_control_statements(out);
  // Like the checker's warnings, only on a mission without errors: the MEG needs one.
  check_mission_logic({out.meg, out.mission, out.fleet, out.checked.drone_types, out.settings}, diags);
  if (diags.has_errors()) return false;
  if (keep == Keep::deployment_graphs) drop_statements(out);
  out.mdgs = build_mdgs(out.meg);
  return true;
}

bool compile_file(const std::string& path, const std::string& fleet_path, Diagnostics& diags,
                  Compilation& out, Keep keep) {
  // A fleet file with errors still yields the parts that parsed, and the mission is checked
  // against them, so one run lists the errors of both files.
  fleet::Fleet fleet;
  if (!fleet_path.empty()) fleet::load_fleet(fleet_path, fleet, diags);
  auto source = std::make_shared<SourceFile>();
  std::string error;
  if (!read_source_file(path, *source, error)) {
    diags.error(nullptr, {},
                "cannot read mission file '" + path + "': " + error + "; give the path of the mission's .eamos file");
    return false;
  }
  bool fleet_ok = !diags.has_errors();
  return compile(std::move(source), fleet, diags, out, {}, keep) && fleet_ok;
}

}  // namespace eamos::graph
