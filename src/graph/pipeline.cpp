#include "graph/pipeline.h"

#include "graph/static_checks.h"
#include "lang/parser.h"

namespace eamos::graph {

namespace {

/// After the last check, a deployment needs of the statements nothing: the MEG's
/// arguments and conditions point into Mission::expressions, which stays. The rest, a fifth
/// of a large mission's memory, is freed before the MDGs and the files are made, which
/// reuse it.
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
  out.amt = build_amt(out.mission);
  out.meg = build_meg(out.amt, out.mission);
  // The AMT is as large as the MEG; freed before the logic check and the MDGs reuse its memory.
  if (keep == Keep::deployment_graphs) out.amt = Amt{};
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
    diags.error(nullptr, {}, "cannot read mission file '" + path + "': " + error);
    return false;
  }
  bool fleet_ok = !diags.has_errors();
  return compile(std::move(source), fleet, diags, out, {}, keep) && fleet_ok;
}

}  // namespace eamos::graph
