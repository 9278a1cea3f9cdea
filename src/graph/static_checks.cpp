#include "graph/static_checks.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <tuple>

#include "diag/number.h"

namespace eamos::graph {

using diag::number_text;

namespace {

using lang::ControlKind;
using lang::Expr;
using lang::ExprKind;
using lang::Op;

constexpr double kInf = std::numeric_limits<double>::infinity();
/// How far a drone standing on the ground may read from where it stands: the GPS and
/// barometer estimate of a real vehicle drifts by up to a metre while it stands still.
constexpr double kStandingSlack = 1.0;

// ---------------------------------------------------------------------------------------
// Values as far as they are known: an interval for numbers, true/false/unknown for booleans.

struct Abstract {
  bool boolean = false;
  int truth = -1;  ///< boolean: -1 unknown, 0 false, 1 true
  double lo = -kInf;
  double hi = kInf;
};

Abstract truth_of(int t) {
  Abstract a;
  a.boolean = true;
  a.truth = t;
  return a;
}

Abstract interval(double lo, double hi) {
  Abstract a;
  if (std::isnan(lo) || std::isnan(hi)) return a;  // inf - inf: nothing is known
  a.lo = lo;
  a.hi = hi;
  return a;
}

Abstract corners(double a, double b, double c, double d) {
  double v[] = {a, b, c, d};
  for (double x : v)
    if (std::isnan(x)) return Abstract{};
  return interval(*std::min_element(v, v + 4), *std::max_element(v, v + 4));
}

Abstract arithmetic(Op op, const Abstract& l, const Abstract& r) {
  switch (op) {
    case Op::add: return interval(l.lo + r.lo, l.hi + r.hi);
    case Op::sub: return interval(l.lo - r.hi, l.hi - r.lo);
    case Op::mul: return corners(l.lo * r.lo, l.lo * r.hi, l.hi * r.lo, l.hi * r.hi);
    case Op::div:
      if (r.lo <= 0.0 && r.hi >= 0.0) return Abstract{};  // may divide by zero: unknown
      return corners(l.lo / r.lo, l.lo / r.hi, l.hi / r.lo, l.hi / r.hi);
    default: return Abstract{};
  }
}

/// l < r (strict) or l <= r.
int less(const Abstract& l, const Abstract& r, bool strict) {
  if (strict ? l.hi < r.lo : l.hi <= r.lo) return 1;
  if (strict ? l.lo >= r.hi : l.lo > r.hi) return 0;
  return -1;
}

int equal(const Abstract& l, const Abstract& r) {
  if (l.boolean) return l.truth < 0 || r.truth < 0 ? -1 : l.truth == r.truth;
  if (l.lo == l.hi && r.lo == r.hi && l.lo == r.lo) return 1;
  if (l.hi < r.lo || r.hi < l.lo) return 0;
  return -1;
}

int negate(int t) { return t < 0 ? -1 : 1 - t; }

Abstract combine(Op op, const Abstract& l, const Abstract& r) {
  switch (op) {
    case Op::lt: return truth_of(less(l, r, true));
    case Op::le: return truth_of(less(l, r, false));
    case Op::gt: return truth_of(less(r, l, true));
    case Op::ge: return truth_of(less(r, l, false));
    case Op::eq: return truth_of(equal(l, r));
    case Op::ne: return truth_of(negate(equal(l, r)));
    case Op::and_:
      return truth_of(l.truth == 0 || r.truth == 0 ? 0 : l.truth == 1 && r.truth == 1 ? 1 : -1);
    case Op::or_:
      return truth_of(l.truth == 1 || r.truth == 1 ? 1 : l.truth == 0 && r.truth == 0 ? 0 : -1);
    default: return arithmetic(op, l, r);
  }
}

bool is_wait(ControlKind k) {
  return k == ControlKind::WaitUntil || k == ControlKind::WaitWhile || k == ControlKind::PauseUntil ||
         k == ControlKind::PauseWhile;
}
bool is_do(ControlKind k) {
  return k == ControlKind::DoUntilSync || k == ControlKind::DoWhileSync || k == ControlKind::DoUntilAsync ||
         k == ControlKind::DoWhileAsync;
}
/// The condition value that lets the structure go on: a Wait/Pause passes, a Repeat runs its
/// body, a Do runs its do-branch.
int go_value(ControlKind k) {
  switch (k) {
    case ControlKind::WaitWhile:
    case ControlKind::PauseWhile:
    case ControlKind::RepeatUntil:
    case ControlKind::DoUntilSync:
    case ControlKind::DoUntilAsync: return 0;
    default: return 1;
  }
}

/// A node that must have started (`via` any) or decided on an outcome other than `via`'s
/// exclusion before another node can start.
struct Pred {
  int node;
  Branch via;
};

/// What one property of one drone is known to be while a condition is evaluated.
struct Fact {
  Abstract value;
  std::string why;  ///< "" when nothing is known
  int action = -1;  ///< the MEG action the fact rests on (a Land), -1 for none
};

enum class Finding {
  wait_never_ends,
  wait_never_waits,
  branch_never_runs_then,
  branch_never_runs_else,
  loop_body_never_runs,
  loop_never_ends,
  do_never_starts,
  done_never_runs,
};

struct Report {
  Severity severity = Severity::error;
  std::string message;
  std::vector<std::pair<SourceLocation, std::string>> notes;
  int count = 0;
  bool every_instance = false;  ///< reported only when every MEG instance of the statement has it
};

class LogicChecker {
 public:
  LogicChecker(const StaticCheckInput& in, Diagnostics& diags, const StaticCheckLimits& limits)
      : in_(in), meg_(in.meg), diags_(diags), limits_(limits) {}

  void run() {
    if (!build_order()) return;
    index_actions();
    mark_cancellable();
    for (const MegNode& n : meg_.nodes)
      if (n.kind == MegKind::condition) {
        ++instances_[key(n.loc)];
        if (!exhausted_) check_condition(n.id);
      }
    if (!exhausted_) check_deadlocks();
    emit();
  }

 private:
  static std::pair<int, int> key(SourceLocation l) { return {l.line, l.col}; }

  // --- graph order ----------------------------------------------------------------------

  /// The nodes each node cannot start before: its execution predecessors, except for the
  /// terminals of an If or a Do, which end by their own branch or by a partner's release and
  /// so are known only to come after their condition. Back arcs are left out: the first run
  /// of a loop's condition does not wait for the body.
  bool build_order() {
    std::size_t n = meg_.nodes.size();
    // Every node's predecessors in one array, the nodes in order, and their successors
    // likewise: a vector per node was a million allocations in a large mission.
    pred_start_.assign(n + 1, 0);
    pred_list_.clear();
    for (const MegNode& node : meg_.nodes) {
      pred_start_[node.id] = static_cast<int>(pred_list_.size());
      add_preds(node);
    }
    pred_start_[n] = static_cast<int>(pred_list_.size());
    std::vector<int> waiting(n, 0), succ_start(n + 1, 0), succ(pred_list_.size());
    for (const Pred& p : pred_list_) ++succ_start[p.node + 1];
    for (std::size_t i = 0; i < n; ++i) succ_start[i + 1] += succ_start[i];
    std::vector<int> filled(succ_start.begin(), succ_start.end() - 1);
    for (std::size_t i = 0; i < n; ++i)
      for (const Pred& p : preds(static_cast<int>(i))) {
        ++waiting[i];
        succ[filled[p.node]++] = static_cast<int>(i);
      }
    for (std::size_t i = 0; i < n; ++i)
      if (waiting[i] == 0) order_.push_back(static_cast<int>(i));
    for (std::size_t k = 0; k < order_.size(); ++k)
      for (int j = succ_start[order_[k]]; j < succ_start[order_[k] + 1]; ++j)
        if (--waiting[succ[j]] == 0) order_.push_back(succ[j]);
    position_.assign(n, 0);
    for (std::size_t k = 0; k < order_.size(); ++k) position_[order_[k]] = static_cast<int>(k);
    return order_.size() == n;  // a cycle would be a builder bug: analyse nothing then
  }

  void add_preds(const MegNode& node) {
    if (node.kind == MegKind::terminal && node.owner_condition >= 0) {
      ControlKind k = meg_.nodes[node.owner_condition].control;
      if (k == ControlKind::If || is_do(k)) {
        pred_list_.push_back({node.owner_condition, Branch::any});
        return;
      }
    }
    for (int a : meg_.in(node.id)) {
      const MegArc& arc = meg_.arcs[a];
      if (arc.kind == ArcKind::exec) pred_list_.push_back({arc.from, arc.branch});
    }
  }

  std::span<const Pred> preds(int node) const {
    return {pred_list_.data() + pred_start_[node], static_cast<std::size_t>(pred_start_[node + 1] - pred_start_[node])};
  }

  bool spend(long long visits) {
    if (exhausted_ || visits_ + visits > limits_.max_node_visits) {
      exhausted_ = true;
      return false;
    }
    visits_ += visits;
    return true;
  }

  /// Nodes that cannot start before one of `seeds` has been reached and has taken an
  /// outcome other than `excluded` (a seed's arcs of those branches do not count).
  std::vector<char> after(const std::vector<int>& seeds, std::initializer_list<Branch> excluded = {}) {
    std::vector<char> seed(meg_.nodes.size(), 0), mark(meg_.nodes.size(), 0);
    // A node's predecessors come before it in the order, so nothing before the first seed
    // can be marked: the walk starts there (on average half the graph for each condition).
    std::size_t first = order_.size();
    for (int s : seeds) {
      seed[s] = 1;
      first = std::min(first, static_cast<std::size_t>(position_[s]));
    }
    for (std::size_t k = first; k < order_.size(); ++k) {
      int x = order_[k];
      for (const Pred& p : preds(x)) {
        bool counts = seed[p.node] && std::find(excluded.begin(), excluded.end(), p.via) == excluded.end();
        if (counts || mark[p.node]) {
          mark[x] = 1;
          break;
        }
      }
    }
    return mark;
  }

  /// Nodes that have ended before `node` starts, on every flight.
  const std::vector<char>& before(int node) {
    auto it = before_.find(node);
    if (it != before_.end()) return it->second;
    std::vector<char> mark(meg_.nodes.size(), 0);
    // Past the budget nothing is known to come before: every fact resting on it is dropped.
    if (!spend(static_cast<long long>(meg_.nodes.size()))) return before_.emplace(node, std::move(mark)).first->second;
    std::vector<int> work{node};
    while (!work.empty()) {
      int x = work.back();
      work.pop_back();
      for (const Pred& p : preds(x))
        if (!mark[p.node]) {
          mark[p.node] = 1;
          work.push_back(p.node);
        }
    }
    return before_.emplace(node, std::move(mark)).first->second;
  }

  // --- actions --------------------------------------------------------------------------

  /// Per drone, its actions that can move it (motion, and any action the catalog does not
  /// class) and those that can also change Armed (system actions: Arm, Disarm).
  void index_actions() {
    int drones = static_cast<int>(in_.mission.drones.size());
    moving_.assign(drones, {});
    arming_.assign(drones, {});
    for (const MegNode& n : meg_.nodes) {
      if (n.kind != MegKind::action || n.drone < 0 || n.drone >= drones) continue;
      const fleet::ActionSpec* spec = in_.types[n.drone].find_action(n.name);
      fleet::ActionClass k = spec ? spec->action_class : fleet::ActionClass::motion;
      if (k == fleet::ActionClass::motion) moving_[n.drone].push_back(n.id);
      if (k != fleet::ActionClass::payload) arming_[n.drone].push_back(n.id);
    }
    auto by_position = [this](int a, int b) { return position_[a] < position_[b]; };
    for (auto& v : moving_) std::sort(v.begin(), v.end(), by_position);
    for (auto& v : arming_) std::sort(v.begin(), v.end(), by_position);
  }

  /// A cheap necessary test for `fact` knowing anything about `prop` of `drone` at `c`:
  /// an action that comes before `c` in the graph's order cannot wait for `c`, so either no
  /// relevant action comes before it, or the last that does is the Land (Disarm) it stands
  /// after. It spares the pass over the graph for almost every condition of a large mission.
  bool may_be_known(int drone, std::string_view prop, int c) const {
    bool armed = prop == "Armed";
    if (prop != "X" && prop != "Y" && prop != "Z" && prop != "Landed" && !armed) return false;
    const std::vector<int>& relevant = armed ? arming_[drone] : moving_[drone];
    auto it = std::lower_bound(relevant.begin(), relevant.end(), c,
                               [this](int a, int node) { return position_[a] < position_[node]; });
    if (it == relevant.begin()) return true;
    return meg_.nodes[*std::prev(it)].name == (armed ? "Disarm" : "Land");
  }

  bool any_may_be_known(const Expr* e, int c) const {
    if (!e) return false;
    if (e->kind == ExprKind::property && e->drone_index >= 0 && may_be_known(e->drone_index, e->property, c))
      return true;
    return any_may_be_known(e->lhs, c) || any_may_be_known(e->rhs, c);
  }

  /// Nodes a Do may cancel: a wait among them can end by cancellation, never for ever.
  void mark_cancellable() {
    cancellable_.assign(meg_.nodes.size(), 0);
    for (const ConditionLists& lists : meg_.condition_lists)
      for (int c : lists.cancels) cancellable_[c] = 1;
  }

  std::string action_text(int node) const {
    const MegNode& n = meg_.nodes[node];
    return in_.mission.drones[n.drone].name + "." + n.name + " at line " + std::to_string(n.loc.line);
  }

  // --- what a drone's property is known to be ---------------------------------------------

  /// How far a drone's relevant actions (motions, or those that can change Armed) can
  /// have run by the time a condition is evaluated, given the actions that cannot have
  /// started yet: none, or all up to a last one that every other has ended before.
  struct Standing {
    bool summarised = false;
    int early = 0;   ///< relevant actions that may have started
    int last = -1;   ///< the one of them last in the graph's order
    bool settled = false;  ///< every other early action ends before `last` starts
  };

  /// What may have run by a condition: `later` marks the nodes that cannot have started.
  /// Empty when nothing about positions or arming can be known (see may_be_known).
  struct Knowledge {
    std::vector<char> later;
    std::vector<std::array<Standing, 2>> standing;  ///< per drone: [moving, arming]
  };

  Knowledge knowledge(std::vector<char> later) {
    Knowledge k;
    k.later = std::move(later);
    k.standing.assign(in_.mission.drones.size(), {});
    return k;
  }

  const Standing& standing(Knowledge& k, int drone, bool armed) {
    Standing& st = k.standing[drone][armed ? 1 : 0];
    if (st.summarised) return st;
    st.summarised = true;
    const std::vector<int>& relevant = armed ? arming_[drone] : moving_[drone];
    for (int a : relevant)  // sorted by position: the last early one is the latest
      if (!k.later[a]) {
        ++st.early;
        st.last = a;
      }
    if (st.early == 0 || meg_.nodes[st.last].name != (armed ? "Disarm" : "Land")) return st;
    const std::vector<char>& first = before(st.last);
    st.settled = std::all_of(relevant.begin(), relevant.end(),
                             [&](int b) { return k.later[b] || b == st.last || first[b]; });
    return st;
  }

  /// `prop` of `drone` while condition `c` is evaluated. A drone none of whose relevant
  /// actions can have started stands where the mission started it; one whose last such
  /// action is a Land (or, for Armed, a Disarm) that has ended before `c`, every other
  /// having ended before that, stands where it landed.
  Fact fact(int drone, std::string_view prop, int c, Knowledge& k) {
    const std::string& name = in_.mission.drones[drone].name;
    Fact f;
    if (prop.rfind("Sensor", 0) == 0) {
      if (const fleet::SensorRange* r = in_.fleet.sensor_range(name, std::string(prop))) {
        f.value = interval(r->low, r->high);
        f.why = name + "." + std::string(prop) + "() reads " + number_text(r->low) + " to " + number_text(r->high) +
                " (its range in the fleet file)";
      }
      return f;
    }
    bool armed = prop == "Armed";
    if (prop != "X" && prop != "Y" && prop != "Z" && prop != "Landed" && !armed) return f;  // Battery
    if (k.later.empty()) return f;  // the caller knows nothing can be known (may_be_known)
    const Standing& st = standing(k, drone, armed);
    if (st.early == 0) return standing_at_start(drone, prop);
    if (!st.settled || !before(c)[st.last]) return f;
    return armed ? disarmed(drone, st.last) : landed(drone, prop, st.last);
  }

  Fact standing_at_start(int drone, std::string_view prop) const {
    const std::string& name = in_.mission.drones[drone].name;
    const fleet::Vec3& home = in_.settings[drone].home;
    auto ov = in_.fleet.overrides.find(name);
    bool home_declared = ov != in_.fleet.overrides.end() && ov->second.home;
    std::string start = name + " has no action that can have run by then";
    Fact f;
    if (prop == "Landed") {
      f.value = truth_of(1);
      f.why = start + ", so it still stands on the ground";
    } else if (prop == "Armed") {
      f.value = truth_of(0);
      f.why = start + ", so it is still disarmed";
    } else if (prop == "Z") {
      f.value = interval(home.z - kStandingSlack, home.z + kStandingSlack);
      f.why = start + ", so " + name + ".Z() stays within " + number_text(kStandingSlack) + " m of its ground z = " +
              number_text(home.z);
    } else if (home_declared) {  // X, Y: only a declared home says where it stands
      double v = prop == "X" ? home.x : home.y;
      f.value = interval(v - kStandingSlack, v + kStandingSlack);
      f.why = start + ", so " + name + "." + std::string(prop) + "() stays within " + number_text(kStandingSlack) +
              " m of its home " + (prop == "X" ? "x" : "y") + " = " + number_text(v);
    }
    return f;
  }

  Fact landed(int drone, std::string_view prop, int land) const {
    const std::string& name = in_.mission.drones[drone].name;
    const fleet::Vec3& home = in_.settings[drone].home;
    std::string done = name + " has landed by then on every path (" + action_text(land) +
                       ") and none of its later motions can run first";
    Fact f;
    f.action = land;
    if (prop == "Landed") {
      f.value = truth_of(1);
      f.why = done + ", so it stays on the ground";
    } else if (prop == "Z") {
      f.value = interval(home.z - kStandingSlack, home.z + kStandingSlack);
      f.why = done + ", so " + name + ".Z() stays within " + number_text(kStandingSlack) + " m of the ground z = " +
              number_text(home.z);
    }
    return f;  // X, Y: it stays where it landed, which is not known here
  }

  Fact disarmed(int drone, int disarm) const {
    Fact f;
    f.action = disarm;
    f.value = truth_of(0);
    f.why = in_.mission.drones[drone].name + " is disarmed by then on every path (" + action_text(disarm) +
            ") and none of its later actions can run first";
    return f;
  }

  Abstract evaluate(const Expr& e, int c, Knowledge& later, std::vector<std::string>& why) {
    switch (e.kind) {
      case ExprKind::number: return interval(e.number, e.number);
      case ExprKind::boolean: return truth_of(e.boolean ? 1 : 0);
      case ExprKind::property: {
        if (e.drone_index < 0) return e.type == lang::ValueType::boolean ? truth_of(-1) : Abstract{};
        Fact f = fact(e.drone_index, e.property, c, later);
        if (e.type == lang::ValueType::boolean) f.value.boolean = true;
        if (!f.why.empty() && std::find(why.begin(), why.end(), f.why) == why.end()) why.push_back(f.why);
        return f.value;
      }
      case ExprKind::unary: {
        Abstract v = evaluate(*e.lhs, c, later, why);
        if (e.op == Op::not_) return truth_of(negate(v.truth));
        return interval(-v.hi, -v.lo);
      }
      case ExprKind::binary: {
        Abstract l = evaluate(*e.lhs, c, later, why);
        Abstract r = evaluate(*e.rhs, c, later, why);
        return combine(e.op, l, r);
      }
      case ExprKind::name: break;
    }
    return Abstract{};
  }

  /// The truth of condition `c` whenever it is evaluated, -1 when it may differ.
  int truth(int c, Knowledge& later, std::vector<std::string>& why) {
    const MegNode& n = meg_.nodes[c];
    if (!n.condition) return -1;
    why.clear();
    return evaluate(*n.condition, c, later, why).truth;
  }

  // --- per condition --------------------------------------------------------------------

  std::string cond_text(int c) const { return "'" + lang::expr_text(*meg_.nodes[c].condition) + "'"; }

  static std::string because(const std::vector<std::string>& why) {
    std::string out;
    for (std::size_t i = 0; i < why.size(); ++i) out += (i ? "; " : ": ") + why[i];
    return out;
  }

  static const char* value_name(int t) { return t ? "true" : "false"; }

  /// The block a branch of condition `c` runs, from its statement (then/repeat/do/wait
  /// are the first block argument, else/after/done the second).
  std::string branch_name(int c, Role role) const {
    const lang::Statement* s = statement_at(meg_.nodes[c].loc);
    bool first = role == Role::then_ || role == Role::repeat || role == Role::do_ ||
                 role == Role::wait;
    std::size_t index = first ? 0 : 1;
    if (s && index < s->branch_functions.size() && s->branch_functions[index] >= 0)
      return in_.mission.functions[s->branch_functions[index]].name;
    return role_name(role);
  }

  /// The control statement at `loc`; the index is built on the first finding only.
  const lang::Statement* statement_at(SourceLocation loc) const {
    if (statements_.empty())
      for (const auto& f : in_.mission.functions)
        for (const auto& s : f.body)
          if (s.control != ControlKind::none) statements_.emplace(key(s.loc), &s);
    auto it = statements_.find(key(loc));
    return it == statements_.end() ? nullptr : it->second;
  }

  void add(int c, Finding kind, Severity sev, std::string message, bool every_instance) {
    auto k = std::make_tuple(meg_.nodes[c].loc.line, meg_.nodes[c].loc.col, static_cast<int>(kind));
    Report& r = reports_[k];
    if (r.count++ == 0) {
      r.severity = sev;
      r.message = std::move(message);
      r.every_instance = every_instance;
    }
  }

  /// A condition's first verdict, shared by the rules of each kind of structure.
  struct Verdict {
    int c = -1;
    ControlKind kind = ControlKind::none;
    bool known = false;  ///< some read may be known: the pass over the graph was made
    int truth = -1;
    std::vector<std::string> why;
  };

  void check_condition(int c) {
    const MegNode& n = meg_.nodes[c];
    if (!n.condition || n.control == ControlKind::none) return;
    Verdict v;
    v.c = c;
    v.kind = n.control;
    // Without a read that may be known, the condition is judged on literals and sensor
    // ranges alone, and no pass over the graph is needed.
    v.known = any_may_be_known(n.condition, c);
    if (v.known && !spend(2 * static_cast<long long>(meg_.nodes.size()))) return;
    Knowledge later = knowledge(v.known ? after({c}) : std::vector<char>{});
    v.truth = truth(c, later, v.why);
    if (is_wait(v.kind)) judge_wait(v);
    else if (v.kind == ControlKind::If) judge_if(v);
    else if (is_repeat(v.kind)) judge_repeat(v);
    else if (is_do(v.kind)) judge_do(v);
  }

  void judge_wait(const Verdict& v) {
    int c = v.c, t = v.truth;
    std::string name = lang::control_name(v.kind);
    if (t == go_value(v.kind)) {
      add(c, Finding::wait_never_waits, Severity::warning,
          name + " never waits: " + cond_text(c) + " is already " + value_name(t) + " whenever it is reached" +
              because(v.why) + "; remove the wait, or wait for something that can change",
          true);
    } else if (t >= 0 && !cancellable_[c]) {
      add(c, Finding::wait_never_ends, Severity::error,
          name + " can never end: " + cond_text(c) + " is " + value_name(t) +
              " whenever it is reached and nothing can change it" + because(v.why) +
              "; wait for something that happens before this point, or move the wait",
          false);
      singleton_blocked_.insert(c);
    }
  }

  void judge_if(const Verdict& v) {
    int c = v.c, t = v.truth;
    if (t < 0) return;
    std::string taken = branch_name(c, t ? Role::then_ : Role::else_);
    std::string dead = branch_name(c, t ? Role::else_ : Role::then_);
    add(c, t ? Finding::branch_never_runs_else : Finding::branch_never_runs_then, Severity::warning,
        "branch " + dead + " can never run: " + cond_text(c) + " is " + value_name(t) + " whenever this If is reached" +
            because(v.why) + "; only " + taken + " runs: test something that can differ, or call " + taken +
            " directly",
        true);
  }

  void judge_repeat(const Verdict& v) {
    int c = v.c, t = v.truth;
    std::string name = lang::control_name(v.kind);
    if (t >= 0 && t != go_value(v.kind)) {
      add(c, Finding::loop_body_never_runs, Severity::warning,
          "loop body " + branch_name(c, Role::repeat) + " can never run: " + cond_text(c) + " is " + value_name(t) +
              " when " + name + " is first reached" + because(v.why) +
              "; test something that can differ, or remove the loop",
          true);
      return;
    }
    if (v.kind == ControlKind::RepeatFor || cancellable_[c]) return;  // RepeatFor stops at its count
    // Every later evaluation follows a run of the body: its actions count as having run.
    Knowledge once_done = knowledge(v.known ? after({c}, {Branch::repeat}) : std::vector<char>{});
    std::vector<std::string> why;
    int always = truth(c, once_done, why);
    if (always == go_value(v.kind))
      add(c, Finding::loop_never_ends, Severity::error,
          name + " can never end: " + cond_text(c) + " stays " + value_name(always) + " whatever its body " +
              branch_name(c, Role::repeat) + " does" + because(why) +
              "; test something the loop or another drone changes, or use RepeatFor with a count",
          false);
  }

  void judge_do(const Verdict& v) {
    int c = v.c, t = v.truth;
    std::string name = lang::control_name(v.kind);
    if (t >= 0 && t != go_value(v.kind)) {
      add(c, Finding::do_never_starts, Severity::warning,
          "neither " + branch_name(c, Role::do_) + " nor " + branch_name(c, Role::done) + " can ever run: " +
              cond_text(c) + " is " + value_name(t) + " whenever this " + name + " is reached" + because(v.why) +
              "; test something that can differ, or remove the " + name,
          true);
      return;
    }
    // While it watches, the do-branch (and, for Async, what follows) runs.
    Knowledge watched = knowledge(v.known ? after({c}, {Branch::do_, Branch::continue_}) : std::vector<char>{});
    std::vector<std::string> why;
    int always = truth(c, watched, why);
    if (always == go_value(v.kind))
      add(c, Finding::done_never_runs, Severity::warning,
          "branch " + branch_name(c, Role::done) + " can never run: " + cond_text(c) + " stays " +
              value_name(always) + " while " + name + " watches it" + because(why) +
              "; test something that can change while " + branch_name(c, Role::do_) + " runs",
          true);
  }

  // --- deadlock -------------------------------------------------------------------------

  /// The drone whose sequence a wait holds up: the drone of the first action after it.
  int waiter(int w) const {
    std::vector<int> work{w};
    std::set<int> seen{w};
    while (!work.empty()) {
      int x = work.front();
      work.erase(work.begin());
      if (x != w && meg_.nodes[x].kind == MegKind::action) return meg_.nodes[x].drone;
      for (int a : meg_.out(x)) {
        const MegArc& arc = meg_.arcs[a];
        if (arc.kind == ArcKind::exec && seen.insert(arc.to).second && seen.size() < 10000) work.push_back(arc.to);
      }
    }
    return meg_.nodes[w].drone;
  }

  bool blocked(int w, Knowledge& later) {
    std::vector<std::string> why;
    int t = truth(w, later, why);
    return t >= 0 && t != go_value(meg_.nodes[w].control);
  }

  static void collect_reads(const Expr* e, std::set<std::pair<int, std::string_view>>& out) {
    if (!e) return;
    if (e->kind == ExprKind::property && e->drone_index >= 0) out.insert({e->drone_index, e->property});
    collect_reads(e->lhs, out);
    collect_reads(e->rhs, out);
  }

  /// Actions that could change what `w` reads: motions for positions and Landed, motions
  /// and system actions for Armed (sensors and Battery change by themselves).
  std::vector<int> enablers(int w) const {
    std::set<std::pair<int, std::string_view>> reads;
    collect_reads(meg_.nodes[w].condition, reads);
    std::vector<int> out;
    for (const auto& [d, prop] : reads) {
      if (prop == "Armed") out.insert(out.end(), arming_[d].begin(), arming_[d].end());
      else if (prop == "X" || prop == "Y" || prop == "Z" || prop == "Landed")
        out.insert(out.end(), moving_[d].begin(), moving_[d].end());
    }
    return out;
  }

  /// The largest set of waits none of which can end before another of the set has: the
  /// first of them to end would need an action that comes only after one of them ended.
  void check_deadlocks() {
    std::vector<int> set;
    for (const MegNode& n : meg_.nodes)
      if (n.kind == MegKind::condition && is_wait(n.control) && n.condition && !cancellable_[n.id])
        set.push_back(n.id);
    while (!set.empty()) {
      if (!spend(2 * static_cast<long long>(meg_.nodes.size()) * static_cast<long long>(1 + set.size() / 64))) return;
      Knowledge later = knowledge(after(set));
      std::vector<int> kept;
      for (int w : set)
        if (blocked(w, later)) kept.push_back(w);
      if (kept.size() == set.size()) break;
      set = std::move(kept);
    }
    std::vector<int> stuck;
    for (int w : set)
      if (!singleton_blocked_.count(w)) stuck.push_back(w);
    if (stuck.empty()) return;
    explain_deadlocks(set, stuck);
  }

  struct Edge {
    int to = -1;      ///< the wait the enabler comes after
    int action = -1;  ///< the enabler
  };

  void explain_deadlocks(const std::vector<int>& set, const std::vector<int>& stuck) {
    if (!spend(static_cast<long long>(meg_.nodes.size()) * static_cast<long long>(set.size()))) return;
    std::map<int, std::vector<char>> after_one;
    for (int w : set) after_one.emplace(w, after({w}));
    std::map<int, Edge> next;
    for (int w : stuck) {
      const std::vector<char>& own = after_one[w];
      for (int e : enablers(w)) {
        if (own[e]) continue;
        for (int v : set)
          if (v != w && after_one[v][e]) {
            next[w] = {v, e};
            break;
          }
        if (next.count(w)) break;
      }
    }
    std::set<std::vector<int>> reported_cycles;
    for (int w : stuck) {
      if (!next.count(w)) continue;
      std::vector<int> chain{w};
      int x = w;
      while (next.count(x) && std::find(chain.begin(), chain.end(), next[x].to) == chain.end()) {
        x = next[x].to;
        chain.push_back(x);
      }
      // Back at w: a cycle. Otherwise w waits on a wait that never ends (alone, or in a
      // cycle w is not part of).
      if (next.count(x) && next[x].to == w) report_cycle(chain, next, reported_cycles);
      else report_chain(w, next[w]);
    }
  }

  std::string wait_step(int w, const Edge& e) const {
    const MegNode& n = meg_.nodes[w];
    const MegNode& to = meg_.nodes[e.to];
    return in_.mission.drones[waiter(w)].name + " waits at line " + std::to_string(n.loc.line) + " (" +
           lang::control_name(n.control) + " " + cond_text(w) + ") for " + action_text(e.action) +
           ", which runs only after " + in_.mission.drones[waiter(e.to)].name + "'s " +
           lang::control_name(to.control) + " at line " + std::to_string(to.loc.line) + " has ended";
  }

  void report_cycle(const std::vector<int>& chain, std::map<int, Edge>& next,
                    std::set<std::vector<int>>& reported) {
    std::vector<int> locs;
    for (int w : chain) locs.push_back(meg_.nodes[w].loc.line * 100000 + meg_.nodes[w].loc.col);
    std::sort(locs.begin(), locs.end());
    if (!reported.insert(locs).second) return;
    // Point at the wait that comes first in the file, and walk the cycle from it.
    std::size_t head = 0;
    for (std::size_t i = 1; i < chain.size(); ++i) {
      SourceLocation a = meg_.nodes[chain[i]].loc, b = meg_.nodes[chain[head]].loc;
      if (a.line < b.line || (a.line == b.line && a.col < b.col)) head = i;
    }
    std::string message = "deadlock: ";
    std::vector<std::pair<SourceLocation, std::string>> notes;
    for (std::size_t k = 0; k < chain.size(); ++k) {
      int w = chain[(head + k) % chain.size()];
      message += (k ? "; " : "") + wait_step(w, next[w]);
      if (k) notes.push_back({meg_.nodes[w].loc, in_.mission.drones[waiter(w)].name + " waits here, in the deadlock reported at line " +
                                                     std::to_string(meg_.nodes[chain[head]].loc.line)});
    }
    message += "; no drone of the cycle can go first: let one of them wait for something that happens before the others' waits";
    int w = chain[head];
    auto k = std::make_tuple(meg_.nodes[w].loc.line, meg_.nodes[w].loc.col, 100);
    Report& r = reports_[k];
    if (r.count++ == 0) {
      r.message = message;
      r.notes = notes;
    }
  }

  void report_chain(int w, const Edge& e) {
    const MegNode& n = meg_.nodes[w];
    auto k = std::make_tuple(n.loc.line, n.loc.col, 101);
    Report& r = reports_[k];
    if (r.count++ == 0)
      r.message = std::string(lang::control_name(n.control)) + " can never end: " + wait_step(w, e) +
                  ", and that wait can never end (see line " + std::to_string(meg_.nodes[e.to].loc.line) +
                  "); wait for something that happens before it";
  }

  void emit() {
    for (const auto& [k, r] : reports_) {
      auto [line, col, kind] = k;
      if (r.every_instance && r.count != instances_[{line, col}]) continue;
      SourceLocation loc{line, col};
      if (r.severity == Severity::warning) diags_.warning(in_.mission.file, loc, r.message);
      else diags_.error(in_.mission.file, loc, r.message);
      for (const auto& [at, text] : r.notes) diags_.note(in_.mission.file, at, text);
    }
  }

  const StaticCheckInput& in_;
  const Meg& meg_;
  Diagnostics& diags_;
  StaticCheckLimits limits_;
  std::vector<int> pred_start_;  ///< per node (and one past the last): its first entry in pred_list_
  std::vector<Pred> pred_list_;
  std::vector<int> order_;
  std::vector<int> position_;  ///< index of each node in order_
  mutable std::map<std::pair<int, int>, const lang::Statement*> statements_;
  std::map<int, std::vector<char>> before_;
  std::vector<std::vector<int>> moving_;
  std::vector<std::vector<int>> arming_;
  std::vector<char> cancellable_;
  std::set<int> singleton_blocked_;
  std::map<std::pair<int, int>, int> instances_;
  std::map<std::tuple<int, int, int>, Report> reports_;
  long long visits_ = 0;
  bool exhausted_ = false;
};

}  // namespace

void check_mission_logic(const StaticCheckInput& in, Diagnostics& diags, const StaticCheckLimits& limits) {
  LogicChecker(in, diags, limits).run();
}

}  // namespace eamos::graph
