#include "lang/arming.h"

#include <algorithm>
#include <map>
#include <unordered_map>
#include <string>
#include <utility>
#include <vector>

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

bool is_repeat(ControlKind k) {
  return k == ControlKind::RepeatUntil || k == ControlKind::RepeatWhile || k == ControlKind::RepeatFor;
}
bool is_do_sync(ControlKind k) { return k == ControlKind::DoUntilSync || k == ControlKind::DoWhileSync; }
bool is_do_async(ControlKind k) { return k == ControlKind::DoUntilAsync || k == ControlKind::DoWhileAsync; }

/// One drone's Armed state through the mission, memoised per (block, entry state): a block
/// is analysed at most four times per drone however often it is called.
/// Which drones each function may run an action of (through what it calls), found once for
/// the whole fleet, and for each PAR, which of its siblings do for each drone: a drone's
/// analysis then visits only what concerns it. Walking the mission once per drone costs
/// drones × statements (at a thousand drones, most of `eamos run`'s CPU in a show).
class Mentions {
 public:
  explicit Mentions(const Mission& m) : m_(m), drones_(m.functions.size()), state_(m.functions.size(), 0) {}

  bool mentions(int fn, int drone) {
    if (fn < 0) return false;
    const std::vector<int>& list = of(fn);
    return std::binary_search(list.begin(), list.end(), drone);
  }
  bool touches(const Statement& st, int drone) {
    if (st.kind == StatementKind::action) return st.drone_index == drone;
    bool any = mentions(st.function_index, drone);
    for (int b : st.branch_functions) any = mentions(b, drone) || any;
    return any;
  }
  /// The siblings of PAR `fn` that may run an action of `drone`, in body order.
  std::vector<std::size_t> touching(int fn, int drone) {
    auto [it, added] = siblings_.try_emplace(fn);
    if (added) index_siblings(fn, it->second);
    auto range = std::equal_range(it->second.begin(), it->second.end(), std::pair<int, std::size_t>{drone, 0},
                                  [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<std::size_t> out;
    for (auto i = range.first; i != range.second; ++i) out.push_back(i->second);
    return out;
  }

 private:
  const std::vector<int>& of(int fn) {
    if (state_[fn] != 0) return drones_[fn];  // known, or being found (the checker ruled out recursion)
    state_[fn] = 1;
    std::vector<int> list;
    for (const Statement& st : m_.functions[fn].body) add_statement(st, list);
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    drones_[fn] = std::move(list);
    state_[fn] = 2;
    return drones_[fn];
  }
  void add_statement(const Statement& st, std::vector<int>& list) {
    if (st.kind == StatementKind::action) {
      if (st.drone_index >= 0) list.push_back(st.drone_index);
      return;
    }
    auto add = [&](int fn) {
      if (fn < 0) return;
      const std::vector<int>& more = of(fn);
      list.insert(list.end(), more.begin(), more.end());
    };
    add(st.function_index);
    for (int b : st.branch_functions) add(b);
  }
  void index_siblings(int fn, std::vector<std::pair<int, std::size_t>>& index) {
    const std::vector<Statement>& body = m_.functions[fn].body;
    for (std::size_t i = 0; i < body.size(); ++i) {
      std::vector<int> list;
      add_statement(body[i], list);
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
      for (int d : list) index.push_back({d, i});
    }
    std::stable_sort(index.begin(), index.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  }

  const Mission& m_;
  std::vector<std::vector<int>> drones_;  ///< per function: sorted drone indices
  std::vector<char> state_;               ///< per function: 0 unknown, 1 being found, 2 known
  std::unordered_map<int, std::vector<std::pair<int, std::size_t>>> siblings_;  ///< PAR → (drone, sibling)
};

/// Per-function tables of one drone's analysis, kept for the next drone: allocating and
/// clearing them whole for each drone would cost drones × functions. Only the entries a
/// drone touched are cleared.
struct ArmingTables {
  Mentions mentions;
  std::vector<Flow> memo;  ///< per function and entry state
  std::vector<char> recorded;
  std::vector<char> listed;  ///< per function: in `touched`
  std::vector<int> touched;  ///< functions with an entry set
  explicit ArmingTables(const Mission& m)
      : mentions(m), memo(m.functions.size() * 4), recorded(m.functions.size() * 4, 0), listed(m.functions.size(), 0) {}
  void clear() {
    for (int fn : touched) {
      listed[fn] = 0;
      for (std::size_t e = 0; e < 4; ++e) memo[fn * 4 + e] = {}, recorded[fn * 4 + e] = 0;
    }
    touched.clear();
  }
};

class DroneArming {
 public:
  DroneArming(const Mission& m, const fleet::DroneType& type, int drone, std::map<std::pair<int, int>, Finding>& out,
              ArmingTables& tables)
      : m_(m), type_(type), drone_(drone), out_(out), tables_(tables) {}

  void run(int init) { block(init, kDisarmed, true); }

 private:
  bool mentioned(int fn) { return tables_.mentions.mentions(fn, drone_); }

  Flow block(int fn, States entry, bool record) {
    if (fn < 0 || entry == 0 || !mentioned(fn)) return {entry, entry};
    std::size_t slot = static_cast<std::size_t>(fn) * 4 + entry;
    bool cached = tables_.memo[slot].seen != 0;
    if (cached && (!record || tables_.recorded[slot])) return tables_.memo[slot];
    const Function& f = m_.functions[fn];
    Flow flow = f.block == BlockKind::par ? par(fn, entry, record) : seq(f, entry, record);
    tables_.memo[slot] = flow;
    if (record) tables_.recorded[slot] = 1;
    if (!tables_.listed[fn]) tables_.listed[fn] = 1, tables_.touched.push_back(fn);
    return flow;
  }

  Flow seq(const Function& f, States entry, bool record) {
    States s = entry, seen = entry, detached = 0;  // detached: what async work may set at any time
    for (const Statement& st : f.body) {
      Flow step = statement(st, s, record, detached);
      s = step.exit ? step.exit | detached : 0;  // a path that failed stays failed
      seen |= step.seen | s;
    }
    return {s, seen};
  }

  /// Siblings run at once: each starts from the entry or from whatever another sibling
  /// that arms or disarms this drone may have set meanwhile. A sibling without an action of
  /// this drone changes nothing and starts from the entry and every changing sibling's
  /// states; the changing siblings' states are counted per state, so that a PAR of a
  /// thousand drones costs each drone one pass over it, not a thousand.
  Flow par(int fn, States entry, bool record) {
    const Function& f = m_.functions[fn];
    std::vector<std::size_t> touching = tables_.mentions.touching(fn, drone_);
    std::vector<Flow> alone;
    for (std::size_t i : touching) {
      States detached = 0;
      Flow flow = statement(f.body[i], entry, false, detached);
      alone.push_back({static_cast<States>(flow.exit | detached), static_cast<States>(flow.seen | detached)});
    }
    auto changes = [&](std::size_t k) { return alone[k].seen != entry || alone[k].exit != entry; };
    int with[4] = {0, 0, 0, 0};  // changing siblings that may pass through each state bit
    States all = 0;               // the states of every changing sibling
    for (std::size_t k = 0; k < alone.size(); ++k)
      if (changes(k))
        for (States bit : {kArmed, kDisarmed})
          if (alone[k].seen & bit) ++with[bit], all |= bit;
    States exit = 0, seen = entry;
    if (touching.size() < f.body.size()) seen |= all;  // what a sibling that changes nothing starts from
    bool changed = false;
    for (std::size_t k = 0; k < touching.size(); ++k) {
      States start = entry;
      for (States bit : {kArmed, kDisarmed})
        if (with[bit] - (changes(k) && (alone[k].seen & bit) ? 1 : 0) > 0) start |= bit;
      States detached = 0;
      Flow flow = statement(f.body[touching[k]], start, record, detached);
      seen |= flow.seen | detached;
      if (changes(k)) {
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
    const fleet::ActionSpec* spec = type_.find_action(st.callee);
    if (spec && spec->action_class == fleet::ActionClass::system) {
      if (st.callee == "Arm") return {kArmed, static_cast<States>(s | kArmed)};
      if (st.callee == "Disarm") return {kDisarmed, static_cast<States>(s | kDisarmed)};
    }
    if (!spec || spec->action_class != fleet::ActionClass::motion) return {s, s};
    if (record) {
      Finding& f = out_[{st.loc.line, st.loc.col}];
      f.statement = &st;
      f.always = f.always && s == kDisarmed;
      f.some = f.some || (s & kDisarmed);
    }
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
  const fleet::DroneType& type_;
  int drone_;
  std::map<std::pair<int, int>, Finding>& out_;
  ArmingTables& tables_;
};

}  // namespace

void check_armed_before_motion(const Mission& mission, const std::vector<fleet::DroneType>& types,
                               Diagnostics& diags) {
  if (mission.init_function < 0) return;
  std::map<std::pair<int, int>, Finding> findings;
  ArmingTables tables(mission);
  for (std::size_t d = 0; d < mission.drones.size() && d < types.size(); ++d) {
    DroneArming(mission, types[d], static_cast<int>(d), findings, tables).run(mission.init_function);
    tables.clear();
  }
  for (const auto& [at, f] : findings) {
    if (!f.some) continue;
    const Statement& st = *f.statement;
    std::string call = st.drone + "." + st.callee;
    std::string fix = "call " + st.drone + ".Arm() before " + st.callee;
    if (f.always)
      diags.error(mission.file, st.loc,
                  call + " runs while " + st.drone + " is disarmed on every path that reaches it, and a drone " +
                      "refuses motion actions until it is armed; " + fix);
    else
      diags.warning(mission.file, st.loc,
                    call + " may run while " + st.drone + " is disarmed: on some path that reaches it no " +
                        st.drone + ".Arm() has run since the start or the last " + st.drone + ".Disarm(); " + fix +
                        " on every path");
  }
}

}  // namespace eamos::lang
