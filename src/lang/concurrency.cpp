#include "lang/concurrency.h"

#include <algorithm>
#include <string>
#include <string_view>

namespace eamos::lang {

namespace {

/// One motion action a drone may run (for the message).
struct MotionSite {
  SourceLocation loc;
  std::string_view action;  ///< the statement's callee, in the AST
};
/// Drone index → one motion action it may run, sorted by drone, one entry per drone: the
/// first one met. An array, not a tree map: a show's every PAR holds the whole fleet, and
/// a map per block with a copy per call was most of this check's time and memory.
using MotionSet = std::vector<std::pair<int, MotionSite>>;

/// `a` with the drones of `b` it lacks (a's site where both have one).
MotionSet unite(const MotionSet& a, const MotionSet& b) {
  MotionSet out;
  out.reserve(a.size() + b.size());
  std::size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    if (j == b.size() || (i < a.size() && a[i].first <= b[j].first)) {
      if (j < b.size() && a[i].first == b[j].first) ++j;
      out.push_back(a[i++]);
    } else {
      out.push_back(b[j++]);
    }
  }
  return out;
}

/// The motions of the statements met so far in one block, by drone: a stamp per drone
/// says whether the drone is in, so each statement costs its own drones, not the block's.
class Running {
 public:
  explicit Running(std::size_t drones) : stamp_(drones, 0), site_(drones) {}

  /// Empties it in constant time for the next block.
  void clear() {
    ++now_;
    drones_.clear();
  }
  const MotionSite* find(int drone) const { return stamp_[drone] == now_ ? &site_[drone] : nullptr; }
  void insert(const MotionSet& set) {
    for (const auto& [drone, site] : set)
      if (stamp_[drone] != now_) {
        stamp_[drone] = now_;
        site_[drone] = site;
        drones_.push_back(drone);
      }
  }
  MotionSet sorted() {
    std::sort(drones_.begin(), drones_.end());
    MotionSet out;
    out.reserve(drones_.size());
    for (int d : drones_) out.push_back({d, site_[d]});
    return out;
  }

 private:
  std::vector<unsigned> stamp_;
  std::vector<MotionSite> site_;
  std::vector<int> drones_;  ///< in, in the order they came
  unsigned now_ = 1;
};

class MotionAnalysis {
 public:
  MotionAnalysis(const Mission& m, const std::vector<fleet::DroneType>& types, Diagnostics& diags)
      : m_(m), types_(types), diags_(diags), memo_(m.functions.size()), done_(m.functions.size()),
        all_(m.drones.size()), launched_(m.drones.size()) {}

  void run() {
    for (std::size_t i = 0; i < m_.functions.size(); ++i) of_function(static_cast<int>(i));
  }

 private:
  /// The callees first, iteratively (calls nest as deep as the mission's functions), then
  /// each block once its callees are known: the running sets are then used by one block
  /// at a time.
  const MotionSet& of_function(int root) {
    std::vector<std::pair<int, std::size_t>> stack;  // (function, next statement to look at)
    if (!done_[root]) stack.push_back({root, 0});
    while (!stack.empty()) {
      auto [fn, next] = stack.back();
      done_[fn] = true;  // the checker has ruled out recursion; this only guards re-entry
      const std::vector<Statement>& body = m_.functions[fn].body;
      int pending = -1;
      for (; next < body.size() && pending < 0; next += pending < 0 ? 1 : 0) pending = first_pending(body[next]);
      stack.back().second = next;
      if (pending >= 0) {
        stack.push_back({pending, 0});
        continue;
      }
      analyse(fn);
      stack.pop_back();
    }
    return memo_[root];
  }

  /// A block the statement calls that is not analysed yet, or -1.
  int first_pending(const Statement& s) const {
    if (s.kind == StatementKind::action) return -1;
    if (s.function_index >= 0 && !done_[s.function_index]) return s.function_index;
    for (int fn : s.branch_functions)
      if (fn >= 0 && !done_[fn]) return fn;
    return -1;
  }

  void analyse(int fn) {
    const Function& f = m_.functions[fn];
    all_.clear();
    launched_.clear();  // motions still running from async work started earlier in a SEQ
    MotionSet own;
    for (const auto& s : f.body) {
      const MotionSet& mine = of_statement(s, own);
      if (f.block == BlockKind::par) report_overlap(all_, mine, s, f.name, false);
      else report_overlap(launched_, mine, s, f.name, true);
      if (s.kind == StatementKind::async_call || s.control == ControlKind::DoUntilAsync ||
          s.control == ControlKind::DoWhileAsync)
        launched_.insert(mine);
      all_.insert(mine);
    }
    memo_[fn] = all_.sorted();
  }

  /// A statement's motions; `own` holds them when they are not a callee's memo.
  const MotionSet& of_statement(const Statement& s, MotionSet& own) {
    own.clear();
    if (s.kind == StatementKind::action) {
      if (s.drone_index < 0) return own;
      const fleet::ActionSpec* spec = types_[s.drone_index].find_action(s.callee);
      if (spec && spec->action_class == fleet::ActionClass::motion) own.push_back({s.drone_index, {s.callee_loc, s.callee}});
      return own;
    }
    if (s.function_index >= 0) return memo_[s.function_index];
    for (int fn : s.branch_functions)
      if (fn >= 0) own = unite(own, memo_[fn]);
    return own;
  }

  void report_overlap(const Running& running, const MotionSet& next, const Statement& s,
                      const std::string& block, bool after_async) {
    for (const auto& [drone, site] : next) {
      const MotionSite* other = running.find(drone);
      if (!other) continue;
      std::string a = std::string(site.action) + " (line " + std::to_string(site.loc.line) + ")";
      std::string b = std::string(other->action) + " (line " + std::to_string(other->loc.line) + ")";
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
  Running all_;       ///< the block's motions so far
  Running launched_;  ///< a SEQ's motions still running from async work started earlier
};

}  // namespace

void warn_concurrent_motion(const Mission& mission, const std::vector<fleet::DroneType>& types,
                            Diagnostics& diags) {
  MotionAnalysis(mission, types, diags).run();
}

}  // namespace eamos::lang
