#include "lang/arming.h"

#include <algorithm>
#include <span>
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

bool is_do_sync(ControlKind k) { return k == ControlKind::DoUntilSync || k == ControlKind::DoWhileSync; }
bool is_do_async(ControlKind k) { return k == ControlKind::DoUntilAsync || k == ControlKind::DoWhileAsync; }

/// What an action statement does to its drone's Armed state, found once per statement
/// when the index is built rather than by name at every visit.
enum class Effect : unsigned char { none, arm, disarm, motion };

/// A statement of a block that mentions a drone: directly (an action of that drone, with
/// its effect) or through the blocks it calls.
struct Entry {
  int drone = 0;
  int at = 0;  ///< index into the block's body
  /// A plain call's block: entered without reading the statement, one cache miss fewer
  /// per block a drone enters. -1 for any other statement.
  int call = -1;
  Effect effect = Effect::none;
  bool action = false;  ///< an action of this drone: `effect` says all the rule needs
};

/// The statements of one block that mention one drone, in order.
using Mine = std::span<const Entry>;

Effect effect_of(const Statement& s, const std::vector<fleet::DroneType>& types) {
  if (s.kind != StatementKind::action || s.drone_index < 0 || s.drone_index >= static_cast<int>(types.size()))
    return Effect::none;
  const fleet::ActionSpec* spec = types[s.drone_index].find_action(s.callee);
  if (!spec) return Effect::none;
  if (spec->action_class == fleet::ActionClass::system) {
    if (s.callee == "Arm") return Effect::arm;
    if (s.callee == "Disarm") return Effect::disarm;
  }
  return spec->action_class == fleet::ActionClass::motion ? Effect::motion : Effect::none;
}

/// Which drones each function and each statement may arm, disarm or move: a drone's
/// analysis visits only the statements that mention it, so a show where every drone flies
/// in every PAR costs each drone its own statements, not the fleet's. Built once for all
/// drones; its size is the statements times the drones each one reaches.
class Mentions {
 public:
  Mentions(const Mission& m, const std::vector<fleet::DroneType>& types)
      : m_(m), of_function_(m.functions.size()), state_(m.functions.size(), 0) {
    by_function_.resize(m.functions.size());
    for (std::size_t fn = 0; fn < m.functions.size(); ++fn) index(static_cast<int>(fn));
    flatten(types);
  }

  /// The statements of `fn` that mention `drone`, in order: a view into the index. The
  /// drones ask in increasing order (restart() before going back), so each block keeps
  /// where the last drone's statements began and the next drone's follow them: a step or
  /// two instead of a binary search, whose cache misses over a million blocks entered were
  /// most of the rule's time in a 520,000-statement show.
  bool par(int fn) const { return ranges_[fn].par; }

  Mine statements(int fn, int drone) {
    Range& r = ranges_[fn];
    unsigned first = r.next;
    while (first < r.end && entries_[first].drone < drone) ++first;
    unsigned last = first;
    while (last < r.end && entries_[last].drone == drone) ++last;
    r.next = first;  // the same drone may enter the block again
    return {entries_.data() + first, last - first};
  }

  /// Lets the next drone asked about be any drone, not only a later one.
  void restart() {
    unsigned begin = 0;
    for (Range& r : ranges_) {
      r.next = begin;
      begin = r.end;
    }
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
        for_each_callee(body[next], [&](int callee) {
          if (pending < 0 && callee >= 0 && state_[callee] == 0) pending = callee;
        });
      stack.back().second = next;
      if (pending >= 0) {
        stack.push_back({pending, 0});
        continue;
      }
      finish(fn);
      stack.pop_back();
    }
  }

  /// The blocks a statement calls, without a vector per statement (a million of them).
  template <class Each>
  static void for_each_callee(const Statement& s, Each visit) {
    if (s.kind != StatementKind::action && s.function_index >= 0) visit(s.function_index);
    for (int fn : s.branch_functions) visit(fn);
  }

  void finish(int fn) {
    std::vector<std::pair<int, int>>& pairs = by_function_[fn];
    const std::vector<Statement>& body = m_.functions[fn].body;
    for (std::size_t i = 0; i < body.size(); ++i) {
      const Statement& s = body[i];
      int at = static_cast<int>(i);
      if (s.kind == StatementKind::action && s.drone_index >= 0) pairs.push_back({s.drone_index, at});
      for_each_callee(s, [&](int callee) {
        if (callee >= 0 && state_[callee] == 2)  // not a recursive call: the checker reports those
          for (int d : of_function_[callee]) pairs.push_back({d, at});
      });
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    std::vector<int>& drones = of_function_[fn];
    for (const auto& [d, at] : pairs)
      if (drones.empty() || drones.back() != d) drones.push_back(d);
    state_[fn] = 2;
  }

  /// One array for every block's entries, each block's in (drone, statement) order.
  void flatten(const std::vector<fleet::DroneType>& types) {
    std::size_t total = 0;
    for (const auto& pairs : by_function_) total += pairs.size();
    entries_.reserve(total);
    ranges_.resize(by_function_.size());
    for (std::size_t fn = 0; fn < by_function_.size(); ++fn) {
      ranges_[fn].next = static_cast<unsigned>(entries_.size());
      const std::vector<Statement>& body = m_.functions[fn].body;
      for (const auto& [d, at] : by_function_[fn]) {
        const Statement& st = body[at];
        bool action = st.kind == StatementKind::action && st.drone_index == d;
        bool plain_call = st.kind == StatementKind::call && st.control == ControlKind::none;
        entries_.push_back({d, at, plain_call ? st.function_index : -1, action ? effect_of(st, types) : Effect::none,
                            action});
      }
      ranges_[fn].end = static_cast<unsigned>(entries_.size());
      ranges_[fn].par = m_.functions[fn].block == BlockKind::par;
      std::vector<std::pair<int, int>>().swap(by_function_[fn]);
    }
  }

  struct Range {
    unsigned next = 0;  ///< where the last drone asked about starts
    unsigned end = 0;
    bool par = false;   ///< the block's kind, beside its entries
  };

  const Mission& m_;
  std::vector<std::vector<int>> of_function_;                ///< per function: sorted drones
  std::vector<std::vector<std::pair<int, int>>> by_function_;  ///< per function: (drone, statement), until flattened
  std::vector<char> state_;  ///< per function: 0 not seen, 1 being indexed, 2 done
  std::vector<Entry> entries_;
  std::vector<Range> ranges_;  ///< per function: its entries
};

/// One drone's Armed state through the mission, memoised per (block, entry state): a block
/// is analysed at most four times per drone however often it is called. The memo is shared
/// by the drones in turn and reset where the last one wrote, so that a thousand drones do
/// not each clear a table of every function.
class DroneArming {
 public:
  DroneArming(const Mission& m, Mentions& mentions, std::vector<Visit>& out)
      : m_(m), mentions_(mentions), out_(out), memo_(m.functions.size() * 4) {}

  void run(int init, int drone) {
    for (std::size_t slot : touched_) memo_[slot] = Memo{};
    touched_.clear();
    if (drone < drone_) mentions_.restart();
    drone_ = drone;
    block(init, kDisarmed, true);
  }

  /// Statements a drone's analysis has visited so far, over every run: the work done.
  long long visited() const { return visited_; }

 private:
  Flow block(int fn, States entry, bool record) {
    if (fn < 0 || entry == 0) return {entry, entry};
    Mine mine = mentions_.statements(fn, drone_);
    if (mine.empty()) return {entry, entry};
    std::size_t slot = static_cast<std::size_t>(fn) * 4 + entry;
    bool cached = memo_[slot].flow.seen != 0;
    if (cached && (!record || memo_[slot].recorded)) return memo_[slot].flow;
    Flow flow = mentions_.par(fn) ? par(fn, mine, entry, record) : seq(fn, mine, entry, record);
    if (!cached) touched_.push_back(slot);
    memo_[slot].flow = flow;
    if (record) memo_[slot].recorded = true;
    return flow;
  }

  /// Statements that do not mention the drone leave its state as it is, async ones too:
  /// only `mine`, the statements that do, are visited.
  Flow seq(int fn, Mine mine, States entry, bool record) {
    States s = entry, seen = entry, detached = 0;  // detached: what async work may set at any time
    for (const Entry& e : mine) {
      ++visited_;
      Flow step = entered(fn, e, s, record, detached);
      s = step.exit ? step.exit | detached : 0;  // a path that failed stays failed
      seen |= step.seen | s;
    }
    return {s, seen};
  }

  /// Siblings run at once: each starts from the entry or from whatever another sibling
  /// that arms or disarms this drone may have set meanwhile. Siblings that do not mention
  /// the drone neither change it nor see more than the others do.
  Flow par(int fn, Mine mine, States entry, bool record) {
    std::size_t n = mine.size();
    if (n == 1) return par_alone(fn, mine[0], entry, record);
    // Most blocks hold one statement of a drone (a show's PAR: one FlyTo sequence per
    // drone): their scratch stays on the stack, not one allocation per PAR and drone.
    constexpr std::size_t kOnStack = 8;
    Flow alone_small[kOnStack];
    States before_small[kOnStack + 1], after_small[kOnStack + 1];
    std::vector<Flow> alone_large;
    std::vector<States> before_large, after_large;
    Flow* alone = alone_small;
    States* before = before_small;
    States* after = after_small;
    if (n > kOnStack) {
      alone_large.resize(n);
      before_large.resize(n + 1);
      after_large.resize(n + 1);
      alone = alone_large.data();
      before = before_large.data();
      after = after_large.data();
    }
    for (std::size_t j = 0; j < n; ++j) {
      States detached = 0;
      ++visited_;
      Flow flow = entered(fn, mine[j], entry, false, detached);
      alone[j] = {static_cast<States>(flow.exit | detached), static_cast<States>(flow.seen | detached)};
    }
    auto changes = [&](std::size_t i) { return alone[i].seen != entry || alone[i].exit != entry; };
    // What the changing siblings before and after each one may set: each start leaves out
    // only its own sibling, in one pass each way rather than one per pair.
    before[0] = 0;
    after[n] = 0;
    for (std::size_t j = 0; j < n; ++j) before[j + 1] = before[j] | (changes(j) ? alone[j].seen : 0);
    for (std::size_t j = n; j-- > 0;) after[j] = after[j + 1] | (changes(j) ? alone[j].seen : 0);
    States exit = 0, seen = entry;
    bool changed = false;
    for (std::size_t i = 0; i < n; ++i) {
      States start = entry | before[i] | after[i + 1];
      States detached = 0;
      ++visited_;
      Flow flow = entered(fn, mine[i], start, record, detached);
      seen |= flow.seen | detached;
      if (changes(i)) {
        exit |= flow.exit | detached;
        changed = true;
      }
    }
    return {changed ? exit : entry, seen};
  }

  /// A PAR with one statement that mentions the drone (a show's or a squad's PAR: one
  /// sequence per drone): no sibling changes the drone meanwhile, so the statement starts
  /// from the entry, and one pass, recorded, is both its flow alone and the one recorded.
  Flow par_alone(int fn, const Entry& e, States entry, bool record) {
    States detached = 0;
    ++visited_;
    Flow flow = entered(fn, e, entry, record, detached);
    States exit = flow.exit | detached, seen = flow.seen | detached;
    bool changes = seen != entry || exit != entry;
    return {changes ? exit : entry, static_cast<States>(entry | seen)};
  }

  /// The statement of an entry of block `fn`; plain calls and actions that only arm,
  /// disarm or do neither are followed from the entry alone.
  Flow entered(int fn, const Entry& e, States s, bool record, States& detached) {
    if (s == 0) return {0, 0};
    if (e.call >= 0) return block(e.call, s, record);
    if (e.action && (e.effect != Effect::motion || !record)) return effect(e.effect, s);
    return statement(m_.functions[fn].body[e.at], e.effect, s, record, detached);
  }

  static Flow effect(Effect e, States s) {
    if (e == Effect::arm) return {kArmed, static_cast<States>(s | kArmed)};
    if (e == Effect::disarm) return {kDisarmed, static_cast<States>(s | kDisarmed)};
    if (e != Effect::motion) return {s, s};
    return {static_cast<States>(s & kArmed), s};  // a path that runs it disarmed fails here
  }

  Flow statement(const Statement& st, Effect effect, States s, bool record, States& detached) {
    if (s == 0) return {0, 0};
    if (st.kind == StatementKind::action) return action(st, effect, s, record);
    if (st.kind == StatementKind::async_call) {
      Flow f = block(st.function_index, s, record);
      detached |= f.seen;
      return {static_cast<States>(s | f.seen), static_cast<States>(s | f.seen)};
    }
    if (st.control == ControlKind::none) return block(st.function_index, s, record);
    return control(st, s, record, detached);
  }

  Flow action(const Statement& st, Effect e, States s, bool record) {
    if (st.drone_index != drone_) return {s, s};
    if (record && e == Effect::motion) out_.push_back({st.loc, s == kDisarmed, (s & kDisarmed) != 0, &st});
    return effect(e, s);
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

  /// A block's flow from one entry state; the four entry states of a block lie together.
  struct Memo {
    Flow flow;
    bool recorded = false;  ///< its visits were recorded
  };

  const Mission& m_;
  Mentions& mentions_;
  std::vector<Visit>& out_;
  int drone_ = -1;
  std::vector<Memo> memo_;
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
  Mentions mentions(mission, types);
  DroneArming arming(mission, mentions, visits);
  for (std::size_t d = 0; d < mission.drones.size() && d < types.size(); ++d)
    arming.run(mission.init_function, static_cast<int>(d));
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
