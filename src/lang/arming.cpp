#include "lang/arming.h"

#include <algorithm>
#include <vector>
#include <string>
#include <utility>

namespace eamos::lang {
namespace {

/// What a drone's Armed state may be at a point: a set of these bits; 0 where no flight
/// gets (a path already failed there).
using States = unsigned char;
constexpr States kArmed = 1;
constexpr States kDisarmed = 2;

/// A block's effect from one entry state: where it may end, and every state it may pass
/// through (what concurrent work or a cancellation part-way can leave behind).
struct Flow {
  States exit = 0;
  States seen = 0;
};

struct Finding {
  bool always = true;  ///< disarmed on every instance reached
  bool some = false;   ///< disarmed on some path of some instance
  const Statement* statement = nullptr;
};

/// One visit of a motion action with the drone's possible states there. Visits are
/// appended and merged per statement at the end: a tree map keyed by position, updated per
/// visit, was a third of the rule's time on a 500,000-statement show.
struct Visit {
  SourceLocation at;
  bool disarmed_only = false;  ///< the drone is disarmed on every path reaching this visit
  bool maybe_disarmed = false;
  const Statement* statement = nullptr;
};

bool is_repeat(ControlKind k) {
  return k == ControlKind::RepeatUntil || k == ControlKind::RepeatWhile || k == ControlKind::RepeatFor;
}
bool is_do_sync(ControlKind k) { return k == ControlKind::DoUntilSync || k == ControlKind::DoWhileSync; }
bool is_do_async(ControlKind k) { return k == ControlKind::DoUntilAsync || k == ControlKind::DoWhileAsync; }

/// Which drones each function and each statement may arm, disarm or move: a drone's
/// analysis visits only the statements that mention it, so a show where every drone flies
/// in every PAR costs each drone its own statements, not the fleet's. Built once for all
/// drones; its size is the statements times the drones each one reaches.
class Mentions {
 public:
  explicit Mentions(const Mission& m) : m_(m), of_function_(m.functions.size()), state_(m.functions.size(), 0) {
    by_function_.resize(m.functions.size());
    for (std::size_t fn = 0; fn < m.functions.size(); ++fn) index(static_cast<int>(fn));
  }

  /// The statements of `fn` that mention `drone`, in order (indices into its body).
  std::vector<int> statements(int fn, int drone) const {
    std::vector<int> out;
    const auto& pairs = by_function_[fn];
    auto it = std::lower_bound(pairs.begin(), pairs.end(), std::pair<int, int>{drone, -1});
    for (; it != pairs.end() && it->first == drone; ++it) out.push_back(it->second);
    return out;
  }

  bool mentions(int fn, int drone) const {
    return fn >= 0 && std::binary_search(of_function_[fn].begin(), of_function_[fn].end(), drone);
  }

 private:
  /// Fills of_function_[fn] and by_function_[fn], callees first; iterative, since calls can
  /// nest as deep as the mission's functions.
  void index(int root) {
    std::vector<std::pair<int, std::size_t>> stack;  // (function, next statement to look at)
    if (state_[root] == 0) stack.push_back({root, 0});
    while (!stack.empty()) {
      auto [fn, next] = stack.back();
      state_[fn] = 1;
      const std::vector<Statement>& body = m_.functions[fn].body;
      int pending = -1;  // a callee not indexed yet
      for (; next < body.size() && pending < 0; next += pending < 0 ? 1 : 0)
        for (int callee : callees(body[next]))
          if (callee >= 0 && state_[callee] == 0) {
            pending = callee;
            break;
          }
      stack.back().second = next;
      if (pending >= 0) {
        stack.push_back({pending, 0});
        continue;
      }
      finish(fn);
      stack.pop_back();
    }
  }

  static std::vector<int> callees(const Statement& s) {
    std::vector<int> out;
    if (s.kind != StatementKind::action && s.function_index >= 0) out.push_back(s.function_index);
    out.insert(out.end(), s.branch_functions.begin(), s.branch_functions.end());
    return out;
  }

  void finish(int fn) {
    std::vector<std::pair<int, int>>& pairs = by_function_[fn];
    const std::vector<Statement>& body = m_.functions[fn].body;
    for (std::size_t i = 0; i < body.size(); ++i) {
      const Statement& s = body[i];
      int at = static_cast<int>(i);
      if (s.kind == StatementKind::action && s.drone_index >= 0) pairs.push_back({s.drone_index, at});
      for (int callee : callees(s))
        if (callee >= 0 && state_[callee] == 2)  // not a recursive call: the checker reports those
          for (int d : of_function_[callee]) pairs.push_back({d, at});
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    std::vector<int>& drones = of_function_[fn];
    for (const auto& [d, at] : pairs)
      if (drones.empty() || drones.back() != d) drones.push_back(d);
    state_[fn] = 2;
  }

  const Mission& m_;
  std::vector<std::vector<int>> of_function_;                ///< per function: sorted drones
  std::vector<std::vector<std::pair<int, int>>> by_function_;  ///< per function: (drone, statement)
  std::vector<char> state_;  ///< per function: 0 not seen, 1 being indexed, 2 done
};

/// One drone's Armed state through the mission, memoised per (block, entry state): a block
/// is analysed at most four times per drone however often it is called. The memo is shared
/// by the drones in turn and reset where the last one wrote, so that a thousand drones do
/// not each clear a table of every function.
class DroneArming {
 public:
  DroneArming(const Mission& m, const Mentions& mentions, std::vector<Visit>& out)
      : m_(m), mentions_(mentions), out_(out), memo_(m.functions.size() * 4), recorded_(m.functions.size() * 4, 0) {}

  void run(int init, const fleet::DroneType& type, int drone) {
    for (std::size_t slot : touched_) {
      memo_[slot] = Flow{};
      recorded_[slot] = 0;
    }
    touched_.clear();
    type_ = &type;
    drone_ = drone;
    block(init, kDisarmed, true);
  }

  /// Statements a drone's analysis has visited so far, over every run: the work done.
  long long visited() const { return visited_; }

 private:
  Flow block(int fn, States entry, bool record) {
    if (fn < 0 || entry == 0 || !mentions_.mentions(fn, drone_)) return {entry, entry};
    std::size_t slot = static_cast<std::size_t>(fn) * 4 + entry;
    bool cached = memo_[slot].seen != 0;
    if (cached && (!record || recorded_[slot])) return memo_[slot];
    const Function& f = m_.functions[fn];
    std::vector<int> mine = mentions_.statements(fn, drone_);
    Flow flow = f.block == BlockKind::par ? par(f, mine, entry, record) : seq(f, mine, entry, record);
    if (!cached) touched_.push_back(slot);
    memo_[slot] = flow;
    if (record) recorded_[slot] = 1;
    return flow;
  }

  /// Statements that do not mention the drone leave its state as it is, async ones too:
  /// only `mine`, the statements that do, are visited.
  Flow seq(const Function& f, const std::vector<int>& mine, States entry, bool record) {
    States s = entry, seen = entry, detached = 0;  // detached: what async work may set at any time
    for (int i : mine) {
      const Statement& st = f.body[i];
      ++visited_;
      Flow step = statement(st, s, record, detached);
      s = step.exit ? step.exit | detached : 0;  // a path that failed stays failed
      seen |= step.seen | s;
    }
    return {s, seen};
  }

  /// Siblings run at once: each starts from the entry or from whatever another sibling
  /// that arms or disarms this drone may have set meanwhile. Siblings that do not mention
  /// the drone neither change it nor see more than the others do.
  Flow par(const Function& f, const std::vector<int>& mine, States entry, bool record) {
    std::vector<Flow> alone;
    for (int i : mine) {
      States detached = 0;
      ++visited_;
      Flow flow = statement(f.body[i], entry, false, detached);
      alone.push_back({static_cast<States>(flow.exit | detached), static_cast<States>(flow.seen | detached)});
    }
    auto changes = [&](std::size_t i) { return alone[i].seen != entry || alone[i].exit != entry; };
    // What the changing siblings before and after each one may set: each start leaves out
    // only its own sibling, in one pass each way rather than one per pair.
    std::size_t n = mine.size();
    std::vector<States> before(n + 1, 0), after(n + 1, 0);
    for (std::size_t j = 0; j < n; ++j) before[j + 1] = before[j] | (changes(j) ? alone[j].seen : 0);
    for (std::size_t j = n; j-- > 0;) after[j] = after[j + 1] | (changes(j) ? alone[j].seen : 0);
    States exit = 0, seen = entry;
    bool changed = false;
    for (std::size_t i = 0; i < n; ++i) {
      States start = entry | before[i] | after[i + 1];
      States detached = 0;
      ++visited_;
      Flow flow = statement(f.body[mine[i]], start, record, detached);
      seen |= flow.seen | detached;
      if (changes(i)) {
        exit |= flow.exit | detached;
        changed = true;
      }
    }
    return {changed ? exit : entry, seen};
  }

  Flow statement(const Statement& st, States s, bool record, States& detached) {
    if (s == 0) return {0, 0};
    if (st.kind == StatementKind::action) return action(st, s, record);
    if (st.kind == StatementKind::async_call) {
      Flow f = block(st.function_index, s, record);
      detached |= f.seen;
      return {static_cast<States>(s | f.seen), static_cast<States>(s | f.seen)};
    }
    if (st.control == ControlKind::none) return block(st.function_index, s, record);
    return control(st, s, record, detached);
  }

  Flow action(const Statement& st, States s, bool record) {
    if (st.drone_index != drone_) return {s, s};
    const fleet::ActionSpec* spec = type_->find_action(st.callee);
    if (spec && spec->action_class == fleet::ActionClass::system) {
      if (st.callee == "Arm") return {kArmed, static_cast<States>(s | kArmed)};
      if (st.callee == "Disarm") return {kDisarmed, static_cast<States>(s | kDisarmed)};
    }
    if (!spec || spec->action_class != fleet::ActionClass::motion) return {s, s};
    if (record) out_.push_back({st.loc, s == kDisarmed, (s & kDisarmed) != 0, &st});
    return {static_cast<States>(s & kArmed), s};  // a path that runs it disarmed fails here
  }

  int branch(const Statement& st, std::size_t i) const {
    return i < st.branch_functions.size() ? st.branch_functions[i] : -1;
  }

  Flow control(const Statement& st, States s, bool record, States& detached) {
    ControlKind k = st.control;
    if (k == ControlKind::If) {
      Flow a = block(branch(st, 0), s, record), b = block(branch(st, 1), s, record);
      return {static_cast<States>(a.exit | b.exit), static_cast<States>(a.seen | b.seen)};
    }
    if (is_repeat(k)) {
      States x = s;  // the state at the condition, over every iteration
      for (States before = 0; before != x;) {
        before = x;
        x |= block(branch(st, 0), x, false).exit;
      }
      Flow body = block(branch(st, 0), x, record), after = block(branch(st, 1), x, record);
      return {after.exit, static_cast<States>(x | body.seen | after.seen)};
    }
    if (is_do_sync(k) || is_do_async(k)) {
      // The do-branch may be cancelled at any point; the done-branch then starts from there.
      Flow doing = block(branch(st, 0), s, record);
      Flow done = block(branch(st, 1), s | doing.seen, record);
      States seen = s | doing.seen | done.seen;
      if (is_do_async(k)) {
        detached |= seen;
        return {seen, seen};
      }
      return {static_cast<States>(doing.seen | done.exit), seen};
    }
    return {s, s};  // Wait*, Pause*
  }

  const Mission& m_;
  const Mentions& mentions_;
  std::vector<Visit>& out_;
  const fleet::DroneType* type_ = nullptr;
  int drone_ = -1;
  std::vector<Flow> memo_;
  std::vector<char> recorded_;
  std::vector<std::size_t> touched_;  ///< memo slots written since the last reset
  long long visited_ = 0;
};

/// Per statement position, in source order: disarmed on every visit, or on some.
std::vector<Finding> merge_visits(std::vector<Visit>& visits) {
  auto position = [](const Visit& v) { return std::pair{v.at.line, v.at.col}; };
  std::stable_sort(visits.begin(), visits.end(),
                   [&](const Visit& a, const Visit& b) { return position(a) < position(b); });
  std::vector<Finding> findings;
  for (std::size_t i = 0; i < visits.size(); ++i) {
    if (i == 0 || position(visits[i]) != position(visits[i - 1])) findings.push_back({});
    Finding& f = findings.back();
    f.statement = visits[i].statement;
    f.always = f.always && visits[i].disarmed_only;
    f.some = f.some || visits[i].maybe_disarmed;
  }
  return findings;
}

}  // namespace

void check_armed_before_motion(const Mission& mission, const std::vector<fleet::DroneType>& types,
                               Diagnostics& diags, long long* work) {
  if (mission.init_function < 0) return;
  std::vector<Visit> visits;
  Mentions mentions(mission);
  DroneArming arming(mission, mentions, visits);
  for (std::size_t d = 0; d < mission.drones.size() && d < types.size(); ++d)
    arming.run(mission.init_function, types[d], static_cast<int>(d));
  if (work) *work = arming.visited();
  for (const Finding& f : merge_visits(visits)) {
    if (!f.some) continue;
    const Statement& st = *f.statement;
    std::string call = std::string(st.drone) + "." + std::string(st.callee);
    std::string fix = "call " + std::string(st.drone) + ".Arm() before " + std::string(st.callee);
    if (f.always)
      diags.error(mission.file, st.loc,
                  call + " runs while " + std::string(st.drone) + " is disarmed on every path that reaches it, and a drone " +
                      "refuses motion actions until it is armed; " + fix);
    else
      diags.warning(mission.file, st.loc,
                    call + " may run while " + std::string(st.drone) + " is disarmed: on some path that reaches it no " +
                        std::string(st.drone) + ".Arm() has run since the start or the last " + std::string(st.drone) + ".Disarm(); " + fix +
                        " on every path");
  }
}

}  // namespace eamos::lang
