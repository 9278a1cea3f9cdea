#include "lang/arming.h"

#include <map>
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

bool is_repeat(ControlKind k) {
  return k == ControlKind::RepeatUntil || k == ControlKind::RepeatWhile || k == ControlKind::RepeatFor;
}
bool is_do_sync(ControlKind k) { return k == ControlKind::DoUntilSync || k == ControlKind::DoWhileSync; }
bool is_do_async(ControlKind k) { return k == ControlKind::DoUntilAsync || k == ControlKind::DoWhileAsync; }

/// One drone's Armed state through the mission, memoised per (block, entry state): a block
/// is analysed at most four times per drone however often it is called.
class DroneArming {
 public:
  DroneArming(const Mission& m, const fleet::DroneType& type, int drone, std::map<std::pair<int, int>, Finding>& out)
      : m_(m), type_(type), drone_(drone), out_(out), mentions_(m.functions.size(), 0),
        memo_(m.functions.size() * 4), recorded_(m.functions.size() * 4, 0) {}

  void run(int init) { block(init, kDisarmed, true); }

 private:
  bool mentioned(int fn) {
    if (fn < 0) return false;
    char& known = mentions_[fn];
    if (known) return known == 2;
    known = 1;  // the checker has ruled out recursion; this only guards re-entry
    bool any = false;
    for (const Statement& s : m_.functions[fn].body) {
      if (s.kind == StatementKind::action) any = any || s.drone_index == drone_;
      else if (s.function_index >= 0) any = mentioned(s.function_index) || any;
      for (int b : s.branch_functions) any = mentioned(b) || any;
    }
    known = any ? 2 : 1;
    return any;
  }

  Flow block(int fn, States entry, bool record) {
    if (fn < 0 || entry == 0 || !mentioned(fn)) return {entry, entry};
    std::size_t slot = static_cast<std::size_t>(fn) * 4 + entry;
    bool cached = memo_[slot].seen != 0;
    if (cached && (!record || recorded_[slot])) return memo_[slot];
    const Function& f = m_.functions[fn];
    Flow flow = f.block == BlockKind::par ? par(f, entry, record) : seq(f, entry, record);
    memo_[slot] = flow;
    if (record) recorded_[slot] = 1;
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
  /// that arms or disarms this drone may have set meanwhile.
  Flow par(const Function& f, States entry, bool record) {
    std::vector<Flow> alone;
    for (const Statement& st : f.body) {
      States detached = 0;
      Flow flow = statement(st, entry, false, detached);
      alone.push_back({static_cast<States>(flow.exit | detached), static_cast<States>(flow.seen | detached)});
    }
    auto changes = [&](std::size_t i) { return alone[i].seen != entry || alone[i].exit != entry; };
    States exit = 0, seen = entry;
    bool changed = false;
    for (std::size_t i = 0; i < f.body.size(); ++i) {
      States start = entry;
      for (std::size_t j = 0; j < f.body.size(); ++j)
        if (j != i && changes(j)) start |= alone[j].seen;
      States detached = 0;
      Flow flow = statement(f.body[i], start, record, detached);
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
  std::vector<char> mentions_;  ///< per function: 0 unknown, 1 no action of this drone, 2 some
  std::vector<Flow> memo_;
  std::vector<char> recorded_;
};

}  // namespace

void check_armed_before_motion(const Mission& mission, const std::vector<fleet::DroneType>& types,
                               Diagnostics& diags) {
  if (mission.init_function < 0) return;
  std::map<std::pair<int, int>, Finding> findings;
  for (std::size_t d = 0; d < mission.drones.size() && d < types.size(); ++d)
    DroneArming(mission, types[d], static_cast<int>(d), findings).run(mission.init_function);
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
