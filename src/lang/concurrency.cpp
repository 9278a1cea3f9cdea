#include "lang/concurrency.h"

#include <map>
#include <string>
#include <string_view>

namespace eamos::lang {

namespace {

/// Drone index → one motion action it may run (for the message).
struct MotionSite {
  SourceLocation loc;
  std::string_view action;  ///< the statement's callee, in the AST
};
using MotionSet = std::map<int, MotionSite>;

class MotionAnalysis {
 public:
  MotionAnalysis(const Mission& m, const std::vector<fleet::DroneType>& types, Diagnostics& diags)
      : m_(m), types_(types), diags_(diags), memo_(m.functions.size()), done_(m.functions.size()) {}

  void run() {
    for (std::size_t i = 0; i < m_.functions.size(); ++i) of_function(static_cast<int>(i));
  }

 private:
  const MotionSet& of_function(int fn) {
    if (done_[fn]) return memo_[fn];
    done_[fn] = true;  // the checker has ruled out recursion; this only guards re-entry
    const Function& f = m_.functions[fn];
    MotionSet all;
    MotionSet launched;  // motions still running from async work started earlier in a SEQ
    for (const auto& s : f.body) {
      MotionSet mine = of_statement(s);
      if (f.block == BlockKind::par) report_overlap(all, mine, s, f.name, false);
      else report_overlap(launched, mine, s, f.name, true);
      if (s.kind == StatementKind::async_call || s.control == ControlKind::DoUntilAsync ||
          s.control == ControlKind::DoWhileAsync)
        launched.insert(mine.begin(), mine.end());
      all.insert(mine.begin(), mine.end());
    }
    memo_[fn] = std::move(all);
    return memo_[fn];
  }

  MotionSet of_statement(const Statement& s) {
    MotionSet out;
    if (s.kind == StatementKind::action) {
      if (s.drone_index < 0) return out;
      const fleet::ActionSpec* spec = types_[s.drone_index].find_action(s.callee);
      if (spec && spec->action_class == fleet::ActionClass::motion)
        out[s.drone_index] = {s.callee_loc, s.callee};
      return out;
    }
    if (s.function_index >= 0) return of_function(s.function_index);
    for (int fn : s.branch_functions)
      if (fn >= 0) {
        const MotionSet& sub = of_function(fn);
        out.insert(sub.begin(), sub.end());
      }
    return out;
  }

  void report_overlap(const MotionSet& running, const MotionSet& next, const Statement& s,
                      const std::string& block, bool after_async) {
    for (const auto& [drone, site] : next) {
      auto it = running.find(drone);
      if (it == running.end()) continue;
      std::string a = std::string(site.action) + " (line " + std::to_string(site.loc.line) + ")";
      std::string b = std::string(it->second.action) + " (line " + std::to_string(it->second.loc.line) + ")";
      diags_.warning(m_.file, s.loc,
                     after_async
                         ? "drone '" + m_.drones[drone].name + "' may run two motion actions at the same time: " +
                               a + " may start while " + b + ", launched asynchronously earlier in " + block +
                               ", still runs; it would preempt it"
                         : "drone '" + m_.drones[drone].name + "' may run two motion actions at the same time: " +
                               a + " and " + b + " are in parallel branches of " + block +
                               "; whichever starts later preempts the other");
    }
  }

  const Mission& m_;
  const std::vector<fleet::DroneType>& types_;
  Diagnostics& diags_;
  std::vector<MotionSet> memo_;
  std::vector<bool> done_;
};

}  // namespace

void warn_concurrent_motion(const Mission& mission, const std::vector<fleet::DroneType>& types,
                            Diagnostics& diags) {
  MotionAnalysis(mission, types, diags).run();
}

}  // namespace eamos::lang
