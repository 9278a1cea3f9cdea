#include "lang/checker.h"

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <functional>

#include "lang/altitude.h"
#include "lang/arming.h"
#include "lang/concurrency.h"
#include "lang/exact_compare.h"
#include "lang/literal_arguments.h"
#include "lang/loop_time.h"

namespace eamos::lang {

bool is_block_name(std::string_view name) {
  return (name.rfind("SEQ_", 0) == 0 || name.rfind("PAR_", 0) == 0) && name.size() > 4;
}

namespace {

enum class Param { condition, block, count, seconds };

struct Signature {
  ControlKind kind;
  std::vector<Param> params;
  const char* usage;
  const char* meaning;  ///< docs/language.md §8 in one sentence, for editors (eamos lsp)
};

const std::vector<Signature>& signatures() {
  using P = Param;
  static const std::vector<Signature> table = {
      {ControlKind::If, {P::condition, P::block, P::block}, "If(condition, SEQ_then, SEQ_else)",
       "evaluates the condition once and runs SEQ_then if it is true, else SEQ_else; the next "
       "statement waits for the branch"},
      {ControlKind::WaitUntil, {P::condition, P::block}, "WaitUntil(condition, SEQ_then)",
       "blocks until the condition is true, then runs SEQ_then"},
      {ControlKind::WaitWhile, {P::condition, P::block}, "WaitWhile(condition, SEQ_then)",
       "blocks while the condition is true, then runs SEQ_then"},
      {ControlKind::RepeatUntil, {P::condition, P::block, P::block},
       "RepeatUntil(condition, SEQ_repeat, SEQ_after)",
       "tests the condition before each iteration: while it is false, runs SEQ_repeat; once it is "
       "true, runs SEQ_after once"},
      {ControlKind::RepeatWhile, {P::condition, P::block, P::block},
       "RepeatWhile(condition, SEQ_repeat, SEQ_after)",
       "tests the condition before each iteration: while it is true, runs SEQ_repeat; once it is "
       "false, runs SEQ_after once"},
      {ControlKind::RepeatFor, {P::condition, P::block, P::block, P::count},
       "RepeatFor(condition, SEQ_repeat, SEQ_after, count)",
       "runs SEQ_repeat while the condition is true and at most count times (a whole-number "
       "literal), then SEQ_after once"},
      {ControlKind::PauseUntil, {P::condition}, "PauseUntil(condition)",
       "halts the enclosing sequence until the condition is true"},
      {ControlKind::PauseWhile, {P::condition}, "PauseWhile(condition)",
       "halts the enclosing sequence while the condition is true"},
      {ControlKind::PauseFor, {P::seconds}, "PauseFor(seconds)",
       "halts the enclosing sequence for a number of seconds (a literal)"},
      {ControlKind::DoUntilAsync, {P::condition, P::block, P::block},
       "DoUntilAsync(condition, SEQ_do, SEQ_done)",
       "like DoUntilSync, but the sequence goes on at once and the branches run detached"},
      {ControlKind::DoWhileAsync, {P::condition, P::block, P::block},
       "DoWhileAsync(condition, SEQ_do, SEQ_done)",
       "like DoWhileSync, but the sequence goes on at once and the branches run detached"},
      {ControlKind::DoUntilSync, {P::condition, P::block, P::block},
       "DoUntilSync(condition, SEQ_do, SEQ_done)",
       "if the condition is false, runs SEQ_do while watching it (else nothing); should it turn true "
       "first, SEQ_do is cancelled on every drone and SEQ_done runs; the sequence goes on when SEQ_do or "
       "SEQ_done has ended"},
      {ControlKind::DoWhileSync, {P::condition, P::block, P::block},
       "DoWhileSync(condition, SEQ_do, SEQ_done)",
       "if the condition is true, runs SEQ_do while watching it (else nothing); should it turn false "
       "first, SEQ_do is cancelled on every drone and SEQ_done runs; the sequence goes on when SEQ_do or "
       "SEQ_done has ended"},
  };
  return table;
}

const Signature* signature_of(ControlKind kind) {
  for (const auto& s : signatures())
    if (s.kind == kind) return &s;
  return nullptr;
}

}  // namespace

const char* control_usage(ControlKind kind) {
  const Signature* s = signature_of(kind);
  return s ? s->usage : "";
}

const char* control_meaning(ControlKind kind) {
  const Signature* s = signature_of(kind);
  return s ? s->meaning : "";
}

namespace {

/// Name → index of the first entry of that name: open addressing in one array of slots,
/// each with the name's hash and a view of it. A large mission resolves a million calls
/// among half a million functions; a node-based map missed the cache about four times per
/// look-up, this about twice (the slot, then the name it holds when the hashes agree).
class NameIndex {
 public:
  /// Adds `name` as entry `index` unless the name is there; returns its first entry's index.
  int insert(std::string_view name, int index) {
    if ((count_ + 1) * 2 > slots_.size()) resize(slots_.empty() ? 16 : slots_.size() * 2);
    std::size_t h = std::hash<std::string_view>{}(name);
    for (std::size_t i = h & mask_;; i = (i + 1) & mask_) {
      Slot& s = slots_[i];
      if (s.index < 0) {
        s = {h, name, index};
        ++count_;
        return index;
      }
      if (s.hash == h && s.name == name) return s.index;
    }
  }

  int find(std::string_view name) const {
    if (slots_.empty()) return -1;
    std::size_t h = std::hash<std::string_view>{}(name);
    for (std::size_t i = h & mask_;; i = (i + 1) & mask_) {
      const Slot& s = slots_[i];
      if (s.index < 0) return -1;
      if (s.hash == h && s.name == name) return s.index;
    }
  }

  void reserve(std::size_t n) {
    std::size_t size = 16;
    while (size < 2 * n) size *= 2;
    if (size > slots_.size()) resize(size);
  }

 private:
  struct Slot {
    std::size_t hash = 0;
    std::string_view name;
    int index = -1;
  };

  /// `size` is a power of two: a slot is the hash's low bits.
  void resize(std::size_t size) {
    std::vector<Slot> old = std::move(slots_);
    slots_.assign(size, Slot{});
    mask_ = slots_.size() - 1;
    count_ = 0;
    for (const Slot& s : old)
      if (s.index >= 0) insert(s.name, s.index);
  }

  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
  std::size_t count_ = 0;
};

const char* type_name(ValueType t) {
  switch (t) {
    case ValueType::number: return "number";
    case ValueType::boolean: return "boolean";
    default: return "unknown";
  }
}

class Checker {
 public:
  Checker(Mission& m, const fleet::Fleet& fleet, Diagnostics& diags, const CheckLimits& limits)
      : m_(m), fleet_(fleet), diags_(diags), limits_(limits), file_(m.file) {}

  CheckedMission run();

 private:
  void check_drones();
  void check_functions();
  void check_statement(Function& f, Statement& s);
  void check_action(Statement& s);
  void check_block_call(Statement& s);
  void check_control(Statement& s);
  int resolve_block(const Expr& e);
  ValueType type_of(Expr& e);
  /// `what` and `whose` name the value in a message: "argument of" "FlyTo".
  void expect_type(Expr& e, ValueType want, const char* what, std::string_view whose);
  void check_call_graph();
  void check_unused();
  void error(SourceLocation loc, const std::string& msg) { diags_.error(file_, loc, msg); }
  void warning(SourceLocation loc, const std::string& msg) { diags_.warning(file_, loc, msg); }
  std::vector<std::string> function_names() const;
  std::vector<std::string> drone_names() const;
  void index_names();
  int find_function(std::string_view name) const;
  int find_drone(std::string_view name) const;

  Mission& m_;
  const fleet::Fleet& fleet_;
  Diagnostics& diags_;
  CheckLimits limits_;
  const SourceFile* file_;
  CheckedMission out_;
  // Name → index of the first function and drone of that name. A large mission names
  // thousands of blocks, and Mission::find_* would compare against every one per call.
  NameIndex function_index_;
  NameIndex drone_index_;
  std::vector<int> first_function_;  ///< per function: the first function of its name
  /// Per function, the blocks it calls (check_call_graph fills it, check_unused reads it).
  std::vector<std::vector<std::pair<int, SourceLocation>>> calls_;
};

CheckedMission Checker::run() {
  index_names();
  check_drones();
  check_functions();
  for (auto& f : m_.functions)
    for (auto& s : f.body) check_statement(f, s);
  check_call_graph();
  check_loops_take_time(m_, diags_);
  if (!diags_.has_errors()) {
    check_literal_altitudes(m_, fleet_, diags_);
    check_literal_arguments(m_, diags_);
  }
  if (!diags_.has_errors()) {
    check_unused();
    warn_concurrent_motion(m_, out_.drone_types, diags_);
    check_armed_before_motion(m_, out_.drone_types, diags_);
    warn_exact_comparisons(m_, diags_);
  }
  return std::move(out_);
}

void Checker::index_names() {
  function_index_.reserve(m_.functions.size());
  drone_index_.reserve(m_.drones.size());
  first_function_.reserve(m_.functions.size());
  for (std::size_t i = 0; i < m_.functions.size(); ++i)
    first_function_.push_back(function_index_.insert(m_.functions[i].name, static_cast<int>(i)));
  for (std::size_t i = 0; i < m_.drones.size(); ++i) drone_index_.insert(m_.drones[i].name, static_cast<int>(i));
}

int Checker::find_function(std::string_view name) const { return function_index_.find(name); }

int Checker::find_drone(std::string_view name) const { return drone_index_.find(name); }

std::vector<std::string> Checker::function_names() const {
  std::vector<std::string> names;
  for (const auto& f : m_.functions) names.push_back(f.name);
  return names;
}

std::vector<std::string> Checker::drone_names() const {
  std::vector<std::string> names;
  for (const auto& d : m_.drones) names.push_back(d.name);
  return names;
}

void Checker::check_drones() {
  if (m_.drones.empty())
    error(m_.functions.empty() ? SourceLocation{1, 1} : m_.functions.front().loc,
          "mission declares no drones; declare each with `var Drone1 DroneType` before the functions");
  std::map<std::string, const DroneDecl*> seen;
  for (const auto& d : m_.drones) {
    auto [it, fresh] = seen.emplace(d.name, &d);
    if (!fresh) {
      error(d.loc, "drone '" + d.name + "' is declared twice (first at line " +
                       std::to_string(it->second->loc.line) + "); rename or remove one");
      diags_.note(file_, it->second->loc, "first declared here");
    }
    if (find_function(d.name) >= 0)
      error(d.loc, "'" + d.name + "' is both a drone and a function; rename one");
    // A drone's name is the common name (CN) of its DDS Security certificate, which X.509
    // bounds at 64 characters.
    if (d.name.size() > kMaxDroneNameLength)
      error(d.loc, "drone name '" + d.name.substr(0, 16) + "…' is " + std::to_string(d.name.size()) +
                       " characters long; a drone's DDS Security certificate holds at most " +
                       std::to_string(kMaxDroneNameLength) + ": shorten it");
    out_.drone_types.push_back(fleet_.type_for(d.type));
    fleet_.check_drone(d.name, out_.drone_types.back(), diags_);
  }
  for (const auto& [name, loc] : fleet_.drone_locations)
    if (find_drone(name) < 0 && fleet_.source)
      diags_.warning(fleet_.source.get(), loc,
                     "fleet file describes drone '" + name + "' which the mission does not declare");
}

void Checker::check_functions() {
  for (std::size_t i = 0; i < m_.functions.size(); ++i) {
    Function& f = m_.functions[i];
    int first = first_function_[i];
    if (first != static_cast<int>(i)) {
      error(f.loc, "function '" + f.name + "' is defined twice (first at line " +
                       std::to_string(m_.functions[first].loc.line) + "); rename or remove one");
      diags_.note(file_, m_.functions[first].loc, "first defined here");
      continue;
    }
    if (f.name == "INIT") {
      m_.init_function = static_cast<int>(i);
      continue;
    }
    if (!is_block_name(f.name)) {
      std::string hint = "SEQ_" + f.name;
      error(f.loc, "block name '" + f.name +
                       "' must start with SEQ_ (run in sequence) or PAR_ (run in parallel); "
                       "rename it, e.g. '" + hint + "'");
    }
  }
  if (m_.init_function < 0) {
    SourceLocation at = m_.functions.empty() ? SourceLocation{1, 1} : m_.functions.front().loc;
    error(at, "mission has no entry point; add `func INIT() { ... }`");
  }
}

void Checker::check_statement(Function& f, Statement& s) {
  (void)f;
  switch (s.kind) {
    case StatementKind::action: check_action(s); break;
    case StatementKind::call:
      // No control structure is named like a block: most calls skip the comparison with
      // every structure's name.
      s.control = is_block_name(s.callee) ? ControlKind::none : control_from_name(s.callee);
      if (s.control != ControlKind::none) check_control(s);
      else check_block_call(s);
      break;
    case StatementKind::async_call: {
      int fi = find_function(s.callee);
      if (fi < 0) {
        std::string near = closest_match(s.callee, function_names());
        error(s.callee_loc, "undefined block '" + std::string(s.callee) + "' in async(...)" +
                                (near.empty() ? "; define it with `func " + std::string(s.callee) + "() { ... }`"
                                              : "; did you mean '" + near + "'?"));
      } else if (!is_block_name(s.callee)) {
        error(s.callee_loc, "async(...) needs a SEQ_ or PAR_ block, not '" + std::string(s.callee) + "'");
      } else {
        s.function_index = fi;
      }
      break;
    }
  }
}

void Checker::check_action(Statement& s) {
  s.drone_index = find_drone(s.drone);
  if (s.drone_index < 0) {
    std::string near = closest_match(s.drone, drone_names());
    error(s.loc, "unknown drone '" + std::string(s.drone) + "'" +
                     (near.empty() ? "; declare it with `var " + std::string(s.drone) + " DroneType`"
                                   : "; did you mean '" + near + "'?"));
    for (auto& a : s.args) type_of(*a);
    return;
  }
  const fleet::DroneType& type = out_.drone_types[s.drone_index];
  const fleet::ActionSpec* spec = type.find_action(s.callee);
  if (!spec) {
    const fleet::PropertySpec* prop = type.find_property(s.callee);
    if (prop) {
      error(s.callee_loc, "'" + std::string(s.drone) + "." + std::string(s.callee) +
                              "()' is a property, not an action; read it inside a condition or argument");
    } else {
      std::vector<std::string> actions;
      for (const auto& spec_ : type.actions) actions.push_back(spec_.name);
      std::string near = closest_match(s.callee, actions);
      error(s.callee_loc, "drone '" + std::string(s.drone) + "' of type '" + type.name + "' has no capability '" +
                              std::string(s.callee) + "'" +
                              (near.empty() ? "; see `eamos check --list-capabilities`"
                                            : "; did you mean '" + near + "'?"));
    }
    for (auto& a : s.args) type_of(*a);
    return;
  }
  int n = static_cast<int>(s.args.size());
  if (std::find(spec->arities.begin(), spec->arities.end(), n) == spec->arities.end()) {
    std::string accepted;
    for (std::size_t i = 0; i < spec->arities.size(); ++i)
      accepted += (i ? " or " : "") + std::to_string(spec->arities[i]);
    error(s.callee_loc, std::string(s.callee) + " takes " + accepted + " argument(s), " + std::to_string(n) +
                            " given; write " + std::string(s.drone) + "." + std::string(s.callee) + "(" + spec->params + ")");
  }
  for (auto& a : s.args) expect_type(*a, ValueType::number, "argument of", s.callee);
}

void Checker::check_block_call(Statement& s) {
  int fi = find_function(s.callee);
  if (fi < 0) {
    std::vector<std::string> candidates = function_names();
    for (const auto& sig : signatures()) candidates.push_back(control_name(sig.kind));
    std::string near = closest_match(s.callee, candidates);
    bool is_action = false;
    for (const auto& a : fleet::standard_actions()) is_action |= a.name == s.callee;
    if (find_drone(s.callee) >= 0)
      error(s.callee_loc, "'" + std::string(s.callee) + "' is a drone; call one of its actions, e.g. " +
                              std::string(s.callee) + ".Takeoff(5)");
    else if (is_action)
      error(s.callee_loc, "'" + std::string(s.callee) + "' is an action; call it on a drone, e.g. " +
                              (m_.drones.empty() ? std::string("Drone1") : m_.drones.front().name) + "." +
                              std::string(s.callee) + "(...)");
    else if (near.empty() && !is_block_name(s.callee))
      error(s.callee_loc, "undefined function '" + std::string(s.callee) +
                              "'; blocks are named SEQ_... or PAR_..., control structures are If, WaitUntil, RepeatWhile, …");
    else
      error(s.callee_loc, "undefined function '" + std::string(s.callee) + "'" +
                              (near.empty() ? "; define it with `func " + std::string(s.callee) + "() { ... }`"
                                            : "; did you mean '" + near + "'?"));
    return;
  }
  if (s.callee == "INIT") {
    error(s.callee_loc, "INIT is the entry point and cannot be called; move its body into a SEQ_ block");
    return;
  }
  if (!s.args.empty())
    error(s.args.front()->loc, "blocks take no arguments; write " + std::string(s.callee) + "()");
  s.function_index = fi;
}

int Checker::resolve_block(const Expr& e) {
  if (e.kind != ExprKind::name) {
    error(e.loc, "expected a block name (SEQ_... or PAR_...) here, found '" + expr_text(e) + "'");
    return -1;
  }
  int fi = find_function(e.drone);
  if (fi < 0) {
    std::string near = closest_match(e.drone, function_names());
    error(e.loc, "undefined block '" + std::string(e.drone) + "'" +
                     (near.empty() ? "; define it with `func " + std::string(e.drone) + "() { ... }`"
                                   : "; did you mean '" + near + "'?"));
    return -1;
  }
  if (!is_block_name(e.drone)) {
    error(e.loc, "'" + std::string(e.drone) + "' cannot be a branch; branches are SEQ_ or PAR_ blocks");
    return -1;
  }
  return fi;
}

void Checker::check_control(Statement& s) {
  const Signature* sig = signature_of(s.control);
  if (s.args.size() != sig->params.size()) {
    error(s.callee_loc, std::string(control_name(s.control)) + " takes " +
                            std::to_string(sig->params.size()) + " argument(s), " +
                            std::to_string(s.args.size()) + " given; write " + sig->usage);
  }
  std::size_t n = std::min(s.args.size(), sig->params.size());
  for (std::size_t i = 0; i < n; ++i) {
    Expr& a = *s.args[i];
    switch (sig->params[i]) {
      case Param::condition:
        expect_type(a, ValueType::boolean, "condition of", control_name(s.control));
        break;
      case Param::block: {
        int fi = resolve_block(a);
        s.branch_functions.push_back(fi);
        break;
      }
      case Param::count:
        if (a.kind != ExprKind::number || !a.integer_literal || a.number < 1 || a.number > 1e9)
          error(a.loc, "RepeatFor count must be a positive integer literal (1 to 1000000000), found '" +
                           expr_text(a) + "'");
        break;
      case Param::seconds:
        if (a.kind != ExprKind::number || a.number < 0 || a.number > 1e7)
          error(a.loc, "PauseFor takes a non-negative number of seconds as a literal, found '" +
                           expr_text(a) + "'");
        break;
    }
  }
}

// long: one case per expression kind, each with its own diagnostic; split, the rules would scatter.
ValueType Checker::type_of(Expr& e) {
  switch (e.kind) {
    case ExprKind::number: return e.type = ValueType::number;
    case ExprKind::boolean: return e.type = ValueType::boolean;
    case ExprKind::name: {
      std::string hint = find_drone(e.drone) >= 0
                             ? "; read a property, e.g. " + std::string(e.drone) + ".X()"
                             : find_function(e.drone) >= 0
                                   ? "; a block cannot be used as a value"
                                   : "; property reads are written Drone.Property()";
      error(e.loc, "unknown name '" + std::string(e.drone) + "' in expression" + hint);
      return e.type = ValueType::unknown;
    }
    case ExprKind::property: {
      e.drone_index = find_drone(e.drone);
      if (e.drone_index < 0) {
        std::string near = closest_match(e.drone, drone_names());
        error(e.loc, "unknown drone '" + std::string(e.drone) + "'" +
                         (near.empty() ? "; declare it with `var " + std::string(e.drone) + " DroneType`"
                                       : "; did you mean '" + near + "'?"));
        return e.type = ValueType::unknown;
      }
      const fleet::DroneType& type = out_.drone_types[e.drone_index];
      const fleet::PropertySpec* p = type.find_property(e.property);
      if (!p) {
        std::vector<std::string> props;
        for (const auto& q : type.properties) props.push_back(q.name);
        std::string near = closest_match(e.property, props);
        if (type.find_action(e.property))
          error(e.loc, "'" + std::string(e.property) + "' is an action, not a property; conditions read properties such as " +
                           std::string(e.drone) + ".Landed() or " + std::string(e.drone) + ".Z()");
        else
          error(e.loc, "drone '" + std::string(e.drone) + "' of type '" + type.name + "' has no property '" +
                           std::string(e.property) + "'" +
                           (near.empty() ? "; see `eamos check --list-capabilities`" : "; did you mean '" + near + "'?"));
        return e.type = ValueType::unknown;
      }
      return e.type = p->type == fleet::ValueType::boolean ? ValueType::boolean : ValueType::number;
    }
    case ExprKind::unary: {
      ValueType t = type_of(*e.lhs);
      ValueType want = e.op == Op::neg ? ValueType::number : ValueType::boolean;
      if (t != ValueType::unknown && t != want) {
        error(e.loc, std::string("operator '") + op_text(e.op) + "' needs a " + type_name(want) +
                         ", found " + type_name(t));
        return e.type = ValueType::unknown;
      }
      return e.type = want;
    }
    case ExprKind::binary: {
      ValueType l = type_of(*e.lhs);
      ValueType r = type_of(*e.rhs);
      if (l == ValueType::unknown || r == ValueType::unknown) return e.type = ValueType::unknown;
      ValueType operand = ValueType::number;
      ValueType result = ValueType::number;
      switch (e.op) {
        case Op::add: case Op::sub: case Op::mul: case Op::div: break;
        case Op::lt: case Op::le: case Op::gt: case Op::ge: result = ValueType::boolean; break;
        case Op::and_: case Op::or_: operand = result = ValueType::boolean; break;
        case Op::eq: case Op::ne:
          if (l != r) {
            error(e.loc, std::string("cannot compare ") + type_name(l) + " with " + type_name(r) +
                             " using '" + op_text(e.op) + "'");
            return e.type = ValueType::unknown;
          }
          return e.type = ValueType::boolean;
        default: break;
      }
      if (l != operand || r != operand) {
        error(e.loc, std::string("operator '") + op_text(e.op) + "' needs " + type_name(operand) +
                         "s, found " + type_name(l) + " and " + type_name(r));
        return e.type = ValueType::unknown;
      }
      return e.type = result;
    }
  }
  return ValueType::unknown;
}

void Checker::expect_type(Expr& e, ValueType want, const char* what_text, std::string_view whose) {
  ValueType t = type_of(e);
  if (t == ValueType::unknown || t == want) return;
  // Built only here: a large mission checks hundreds of thousands of values.
  std::string what = std::string(what_text) + " " + std::string(whose);
  if (want == ValueType::boolean)
    error(e.loc, what + " must be boolean, found " + type_name(t) + " '" + expr_text(e) +
                     "'; compare it, e.g. '" + expr_text(e) + " > 0'");
  else
    error(e.loc, what + " must be a number, found " + type_name(t) + " '" + expr_text(e) + "'");
}

// Callees of a function: blocks it calls, launches with async, or names as a branch.
std::vector<std::pair<int, SourceLocation>> callees(const Function& f) {
  std::vector<std::pair<int, SourceLocation>> out;
  for (const auto& s : f.body) {
    if (s.function_index >= 0) out.push_back({s.function_index, s.callee_loc});
    for (std::size_t i = 0, b = 0; i < s.args.size() && b < s.branch_functions.size(); ++i) {
      if (s.args[i]->kind != ExprKind::name) continue;
      if (s.branch_functions[b] >= 0) out.push_back({s.branch_functions[b], s.args[i]->loc});
      ++b;
    }
  }
  return out;
}

// Iterative DFS over the call graph: finds cycles (recursion), the expanded size and the
// depth, without recursing in C++ (a 100,000-deep call chain must not overflow the stack).
void Checker::check_call_graph() {
  std::size_t n = m_.functions.size();
  enum Color { white, grey, black };
  std::vector<Color> color(n, white);
  std::vector<long long> size(n, 0);
  std::vector<int> depth(n, 0);
  std::vector<std::vector<std::pair<int, SourceLocation>>>& edges = calls_;
  edges.resize(n);
  for (std::size_t i = 0; i < n; ++i) edges[i] = callees(m_.functions[i]);
  std::set<int> reported;
  for (std::size_t root = 0; root < n; ++root) {
    if (color[root] != white) continue;
    struct Frame { int fn; std::size_t next; };
    std::vector<Frame> stack{{static_cast<int>(root), 0}};
    color[root] = grey;
    while (!stack.empty()) {
      Frame& top = stack.back();
      if (top.next < edges[top.fn].size()) {
        auto [callee, loc] = edges[top.fn][top.next++];
        if (color[callee] == grey) {
          if (reported.insert(callee).second)
            error(loc, "recursion: '" + m_.functions[callee].name +
                           (callee == top.fn ? "' calls itself"
                                             : "' reaches itself through '" + m_.functions[top.fn].name + "'") +
                           "; blocks are expanded inline, write loops with RepeatUntil/RepeatWhile/RepeatFor");
        } else if (color[callee] == white) {
          color[callee] = grey;
          stack.push_back({callee, 0});
        }
        continue;
      }
      int fn = top.fn;
      long long total = 1;
      int d = 0;
      for (const auto& s : m_.functions[fn].body) total += 1 + static_cast<long long>(s.args.size() > 0);
      for (const auto& [callee, loc] : edges[fn]) {
        total = std::min(total + size[callee], limits_.max_expanded_nodes * 4);
        d = std::max(d, depth[callee] + 1);
      }
      size[fn] = total;
      depth[fn] = d;
      color[fn] = black;
      stack.pop_back();
    }
  }
  if (diags_.has_errors() || m_.init_function < 0) return;
  const Function& init = m_.functions[m_.init_function];
  out_.expanded_statements = size[m_.init_function];
  if (size[m_.init_function] > limits_.max_expanded_nodes)
    error(init.loc, "mission expands to more than " + std::to_string(limits_.max_expanded_nodes) +
                        " nodes (every call instantiates its block); call fewer blocks or split the mission");
  if (depth[m_.init_function] > limits_.max_call_depth)
    error(init.loc, "blocks nest more than " + std::to_string(limits_.max_call_depth) +
                        " calls deep; flatten the call chain");
}

void Checker::check_unused() {
  if (m_.init_function < 0) return;
  std::vector<bool> reached(m_.functions.size(), false);
  std::vector<int> work{m_.init_function};
  reached[m_.init_function] = true;
  while (!work.empty()) {
    int fn = work.back();
    work.pop_back();
    for (const auto& [callee, loc] : calls_[fn])
      if (!reached[callee]) {
        reached[callee] = true;
        work.push_back(callee);
      }
  }
  for (std::size_t i = 0; i < m_.functions.size(); ++i) {
    m_.functions[i].called = reached[i];
    if (!reached[i])
      warning(m_.functions[i].loc, "block '" + m_.functions[i].name +
                                       "' is never called from INIT; call it or remove it");
  }
}

}  // namespace

CheckedMission check_mission(Mission& mission, const fleet::Fleet& fleet, Diagnostics& diags,
                             const CheckLimits& limits) {
  return Checker(mission, fleet, diags, limits).run();
}

}  // namespace eamos::lang
