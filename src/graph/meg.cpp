#include "graph/meg.h"

#include <algorithm>
#include <map>
#include <span>
#include <string_view>

namespace eamos::graph {

int Meg::add_node(MegKind kind, SourceLocation loc) {
  MegNode n;
  n.id = static_cast<int>(nodes.size());
  n.kind = kind;
  n.loc = loc;
  nodes.push_back(std::move(n));
  return nodes.back().id;
}

int Meg::add_arc(int from, int to, ArcKind kind, Branch branch) {
  int id = static_cast<int>(arcs.size());
  arcs.push_back({from, to, kind, branch});
  return id;
}

ConditionLists& Meg::lists_of(int condition) {
  int& index = nodes[condition].lists;
  if (index < 0) {
    index = static_cast<int>(condition_lists.size());
    condition_lists.emplace_back();
  }
  return condition_lists[index];
}

std::span<const int> Meg::terminals(int node) const {
  int index = nodes[node].lists;
  if (index < 0) return {};
  return condition_lists[index].terminals;
}

std::span<const int> Meg::cancels(int node) const {
  int index = nodes[node].lists;
  if (index < 0) return {};
  return condition_lists[index].cancels;
}

namespace {

/// A counting sort of the arcs by one end: start[n] is where node n's arcs begin in list.
void index_by(const std::vector<MegArc>& arcs, std::size_t node_count, int MegArc::*end, std::vector<int>& start,
              std::vector<int>& list) {
  start.assign(node_count + 1, 0);
  for (const MegArc& a : arcs) ++start[a.*end + 1];
  for (std::size_t n = 0; n < node_count; ++n) start[n + 1] += start[n];
  list.resize(arcs.size());
  std::vector<int> next(start.begin(), start.end() - 1);
  for (std::size_t a = 0; a < arcs.size(); ++a) list[next[arcs[a].*end]++] = static_cast<int>(a);
}

}  // namespace

void Meg::index_arcs() {
  index_by(arcs, nodes.size(), &MegArc::from, out_start, out_arcs);
  index_by(arcs, nodes.size(), &MegArc::to, in_start, in_arcs);
}

namespace {

using lang::ControlKind;

/// An open end of the graph built so far: the next node created gets an arc from it.
struct Pending {
  int node;
  Branch branch = Branch::any;
};
using Ends = std::vector<Pending>;

void collect_reads(const lang::Expr* e, std::vector<int>& order) {
  if (!e) return;
  if (e->kind == lang::ExprKind::property && e->drone_index >= 0) order.push_back(e->drone_index);
  collect_reads(e->lhs, order);
  collect_reads(e->rhs, order);
}

std::vector<int> unique_drones(const std::vector<int>& order) {
  std::vector<int> out;
  for (int d : order)
    if (std::find(out.begin(), out.end(), d) == out.end()) out.push_back(d);
  return out;
}

/// One node of the AMT, read from the statements it expands: the MEG is built from the
/// mission itself, so a compile that needs no AMT never holds one (it was as large as the
/// MEG).
struct Node {
  AmtKind kind = AmtKind::seq;
  SourceLocation loc;
  std::string_view name;
  int function = -1;                           ///< init, seq, par: the block it expands
  const lang::Statement* statement = nullptr;  ///< async, action, pause, control
};

class MegBuilder {
 public:
  explicit MegBuilder(const lang::Mission& m)
      : m_(m), first_drone_(m.functions.size(), kNotFound), bounds_(m.functions.size(), -1) {
    meg_.drone_count = static_cast<int>(m.drones.size());
  }

  Meg build() {
    const lang::Function& init = m_.functions[m_.init_function];
    meg_.nodes.reserve(node_bound());
    Node root{AmtKind::init, init.loc, init.name, m_.init_function};
    meg_.init = meg_.add_node(MegKind::init, root.loc);
    meg_.nodes[meg_.init].name = "INIT";
    Ends ends = build_children(root, {{meg_.init}});
    meg_.end = meg_.add_node(MegKind::end, root.loc);
    meg_.nodes[meg_.end].name = "end";
    // One drone holds the end: cloning it onto every drone would cost an arc from each
    // last node to each drone, quadratic in fleet size, for no decision anyone needs.
    meg_.nodes[meg_.end].drone = 0;
    connect(ends, meg_.end);
    meg_.index_arcs();
    return std::move(meg_);
  }

 private:
  static constexpr int kNotFound = -2;

  /// At most the number of MEG nodes the mission turns into: one per init, fork, async
  /// terminal, action and pause, up to three per control structure (its condition and two
  /// terminals), plus the end. Reserving it keeps the node vector from being copied as it
  /// grows, which at 500,000 nodes costs time and a transient third of the MEG's memory.
  std::size_t node_bound() {
    std::size_t bound = 2;  // the init and the end
    for (const lang::Statement& s : m_.functions[m_.init_function].body) bound += statement_bound(s);
    return bound;
  }

  std::size_t block_bound(int f) {
    if (bounds_[f] >= 0) return static_cast<std::size_t>(bounds_[f]);
    std::size_t bound = m_.functions[f].block == lang::BlockKind::par ? 1 : 0;
    for (const lang::Statement& s : m_.functions[f].body) bound += statement_bound(s);
    bounds_[f] = static_cast<long long>(bound);
    return bound;
  }

  std::size_t statement_bound(const lang::Statement& s) {
    switch (s.kind) {
      case lang::StatementKind::action: return 1;
      case lang::StatementKind::async_call: return 1 + block_bound(s.function_index);
      case lang::StatementKind::call: break;
    }
    if (s.control == ControlKind::none) return block_bound(s.function_index);
    if (s.control == ControlKind::PauseFor) return 1;
    std::size_t bound = 3;
    std::span<const Role> roles = branch_roles(s.control);
    for (std::size_t b = 0; b < roles.size() && b < s.branch_functions.size(); ++b)
      bound += block_bound(s.branch_functions[b]);
    return bound;
  }

  /// The AMT node a statement expands into.
  Node child_of(const lang::Statement& s) {
    switch (s.kind) {
      case lang::StatementKind::action: return {AmtKind::action, s.loc, s.callee, -1, &s};
      case lang::StatementKind::async_call: return {AmtKind::async, s.loc, "async", -1, &s};
      case lang::StatementKind::call: break;
    }
    if (s.control == ControlKind::none) return block(s.function_index, s.loc);
    if (s.control == ControlKind::PauseFor) return {AmtKind::pause, s.loc, "PauseFor", -1, &s};
    return {AmtKind::control, s.loc, lang::control_name(s.control), -1, &s};
  }

  /// An instance of block `f` called at `loc`.
  Node block(int f, SourceLocation loc) {
    const lang::Function& fn = m_.functions[f];
    AmtKind kind = fn.block == lang::BlockKind::par ? AmtKind::par : AmtKind::seq;
    return {kind, loc, fn.name, f};
  }

  void connect(const Ends& ends, int to) {
    for (const Pending& p : ends) meg_.add_arc(p.node, to, ArcKind::exec, p.branch);
  }

  /// The drone of the first action in block `f`'s expansion (depth first), or -1; the
  /// same for every instance, so found once per block.
  int first_action_drone(int f) {
    if (first_drone_[f] != kNotFound) return first_drone_[f];
    int drone = kNotFound;
    for (const lang::Statement& s : m_.functions[f].body)
      if ((drone = first_action_drone(s)) != kNotFound) break;
    first_drone_[f] = drone == kNotFound ? -1 : drone;
    return first_drone_[f];
  }

  /// kNotFound when the statement's expansion holds no action.
  int first_action_drone(const lang::Statement& s) {
    if (s.kind == lang::StatementKind::action) return s.drone_index;
    if (s.kind == lang::StatementKind::async_call || s.control == ControlKind::none) {
      int d = first_action_drone(s.function_index);
      return d >= 0 ? d : kNotFound;
    }
    std::span<const Role> roles = branch_roles(s.control);
    for (std::size_t b = 0; b < roles.size() && b < s.branch_functions.size(); ++b) {
      int d = first_action_drone(s.branch_functions[b]);
      if (d >= 0) return d;
    }
    return kNotFound;
  }

  /// The drone of the nearest open end that has one, or -1.
  int drone_of(const Ends& ends) const {
    for (const Pending& p : ends)
      if (meg_.nodes[p.node].drone >= 0) return meg_.nodes[p.node].drone;
    return -1;
  }

  Ends build_children(const Node& n, Ends ends) {
    for (const lang::Statement& s : m_.functions[n.function].body) ends = build(child_of(s), ends);
    return ends;
  }

  Ends build(const Node& n, const Ends& ends) {
    switch (n.kind) {
      case AmtKind::init:
      case AmtKind::seq: return build_children(n, ends);
      case AmtKind::par: return build_par(n, ends);
      case AmtKind::async: return build_async(n, ends);
      case AmtKind::action: return build_action(n, ends);
      case AmtKind::pause: return build_pause(n, ends);
      case AmtKind::control: return build_control(n, ends);
    }
    return ends;
  }

  Ends build_par(const Node& n, const Ends& ends) {
    int fork = meg_.add_node(MegKind::fork, n.loc);
    meg_.nodes[fork].name = n.name;
    connect(ends, fork);
    Ends out;
    const std::vector<lang::Statement>& body = m_.functions[n.function].body;
    for (const lang::Statement& s : body) {
      Ends child = build(child_of(s), {{fork}});
      out.insert(out.end(), child.begin(), child.end());
    }
    if (body.empty()) out.push_back({fork});
    return out;
  }

  // async(F): F starts where the call stands; the sequence goes on from the same point,
  // and F's end goes to a terminal of its own that nothing waits for.
  Ends build_async(const Node& n, const Ends& ends) {
    const lang::Statement& s = *n.statement;
    Node body = block(s.function_index, s.callee_loc);
    Ends body_ends = build(body, ends);
    int t = meg_.add_node(MegKind::terminal, n.loc);
    meg_.nodes[t].name = "async " + std::string(body.name);
    int owner = first_action_drone(s.function_index);
    meg_.nodes[t].drone = owner >= 0 ? owner : std::max(0, drone_of(ends));
    connect(body_ends, t);
    return ends;
  }

  Ends build_action(const Node& n, const Ends& ends) {
    const lang::Statement& s = *n.statement;
    int a = meg_.add_node(MegKind::action, n.loc);
    MegNode& node = meg_.nodes[a];
    node.drone = s.drone_index;
    node.name = n.name;
    node.args.assign(s.args.begin(), s.args.end());
    std::vector<int> order;
    for (const lang::Expr* e : s.args) collect_reads(e, order);
    node.reads = unique_drones(order);
    connect(ends, a);
    return {{a}};
  }

  Ends build_pause(const Node& n, const Ends& ends) {
    int p = meg_.add_node(MegKind::pause, n.loc);
    int owner = drone_of(ends);
    meg_.nodes[p].drone = owner >= 0 ? owner : 0;
    meg_.nodes[p].name = n.name;
    meg_.nodes[p].seconds = n.statement->args[0]->number;
    connect(ends, p);
    return {{p}};
  }

  // The evaluating drone: the one the condition reads most (ties: first read), so that
  // the freshest values are local; a condition on constants goes to the first drone of
  // its branches, then to the drone that ran just before it.
  int condition_owner(const lang::Statement& s, const Ends& ends, const std::vector<int>& order) {
    std::map<int, int> count;
    for (int d : order) ++count[d];
    int best = -1, best_count = 0;
    for (int d : order)
      if (count[d] > best_count) {
        best = d;
        best_count = count[d];
      }
    if (best >= 0) return best;
    std::span<const Role> roles = branch_roles(s.control);
    for (std::size_t b = 0; b < roles.size() && b < s.branch_functions.size(); ++b) {
      int d = first_action_drone(s.branch_functions[b]);
      if (d >= 0) return d;
    }
    int d = drone_of(ends);
    return d >= 0 ? d : 0;
  }

  int add_terminal(const Node& n, int condition, Role role) {
    int t = meg_.add_node(MegKind::terminal, n.loc);
    MegNode& node = meg_.nodes[t];
    node.drone = meg_.nodes[condition].drone;
    node.owner_condition = condition;
    node.role = role;
    node.name = std::string(role_name(role)) + " " + std::string(n.name);
    meg_.lists_of(condition).terminals.push_back(t);
    return t;
  }

  /// Builds the branch of control node `n` with `role` from `from`; `from` itself when the
  /// structure has no such branch.
  Ends build_role(const Node& n, Role role, Ends from) {
    const lang::Statement& s = *n.statement;
    std::span<const Role> roles = branch_roles(s.control);
    for (std::size_t b = 0; b < roles.size() && b < s.branch_functions.size(); ++b)
      if (roles[b] == role) return build(block(s.branch_functions[b], s.args[b + 1]->loc), from);
    return from;
  }

  /// Nodes [first, last) belong to the body of condition `c` unless a body nested inside
  /// already claimed them (inner bodies are built, and marked, first).
  void mark_scope(int first, int last, int c) {
    for (int i = first; i < last; ++i)
      if (meg_.nodes[i].scope < 0) meg_.nodes[i].scope = c;
  }

  /// Builds a branch starting at (condition, branch) and ends it in a new terminal.
  int build_branch(const Node& n, int c, Role role, Branch branch) {
    Ends body_ends = build_role(n, role, {{c, branch}});
    int t = add_terminal(n, c, role);
    connect(body_ends, t);
    return t;
  }

  Ends build_control(const Node& n, const Ends& ends) {
    const lang::Statement& s = *n.statement;
    int c = meg_.add_node(MegKind::condition, n.loc);
    {
      MegNode& node = meg_.nodes[c];
      node.name = n.name;
      node.control = s.control;
      node.condition = s.args[0];
      if (s.control == ControlKind::RepeatFor) node.count = static_cast<long long>(s.args[3]->number);
      std::vector<int> order;
      collect_reads(node.condition, order);
      node.reads = unique_drones(order);
      node.drone = condition_owner(s, ends, order);
    }
    connect(ends, c);
    switch (s.control) {
      case ControlKind::If: {
        int t1 = build_branch(n, c, Role::then_, Branch::true_);
        int t2 = build_branch(n, c, Role::else_, Branch::false_);
        meg_.add_arc(t1, t2, ArcKind::partner);
        meg_.add_arc(t2, t1, ArcKind::partner);
        return {{t1}, {t2}};
      }
      case ControlKind::WaitUntil:
      case ControlKind::WaitWhile: return {{build_branch(n, c, Role::wait, Branch::go)}};
      case ControlKind::PauseUntil:
      case ControlKind::PauseWhile: return {{c, Branch::go}};
      case ControlKind::RepeatUntil:
      case ControlKind::RepeatWhile:
      case ControlKind::RepeatFor: {
        int first = static_cast<int>(meg_.nodes.size());
        int tr = build_branch(n, c, Role::repeat, Branch::repeat);
        mark_scope(first, static_cast<int>(meg_.nodes.size()), c);
        meg_.add_arc(tr, c, ArcKind::back);
        return {{build_branch(n, c, Role::after, Branch::exit)}};
      }
      case ControlKind::DoUntilSync:
      case ControlKind::DoWhileSync:
      case ControlKind::DoUntilAsync:
      case ControlKind::DoWhileAsync: return build_do(n, c);
      default: return {{c}};
    }
  }

  // Do*: the do-branch runs while the condition says "do"; a flip cancels it (every node
  // built for it is in `cancels`) and starts the done-branch. The do-terminal tells the
  // condition to stop watching; the two terminals release each other so that the
  // statement after a Sync Do waits for exactly one of them.
  Ends build_do(const Node& n, int c) {
    ControlKind k = n.statement->control;
    bool sync = k == ControlKind::DoUntilSync || k == ControlKind::DoWhileSync;
    int first = static_cast<int>(meg_.nodes.size());
    Ends body_ends = build_role(n, Role::do_, {{c, Branch::do_}});
    int last = static_cast<int>(meg_.nodes.size());
    std::vector<int>& cancels = meg_.lists_of(c).cancels;
    for (int i = first; i < last; ++i) cancels.push_back(i);
    mark_scope(first, last, c);
    int t_do = add_terminal(n, c, Role::do_);
    connect(body_ends, t_do);
    // "Don't do" releases the do-terminal like a partner would: it ends without its branch.
    meg_.add_arc(c, t_do, ArcKind::partner, Branch::skip);
    meg_.add_arc(t_do, c, ArcKind::stop);
    int t_done = build_branch(n, c, Role::done, Branch::done);
    meg_.add_arc(t_do, t_done, ArcKind::partner);
    meg_.add_arc(t_done, t_do, ArcKind::partner);
    if (sync) return {{t_do}, {t_done}};
    return {{c, Branch::continue_}};
  }

  const lang::Mission& m_;
  Meg meg_;
  std::vector<int> first_drone_;     ///< per function: first_action_drone, kNotFound until known
  std::vector<long long> bounds_;    ///< per function: block_bound, -1 until known
};

}  // namespace

Meg build_meg(const lang::Mission& mission) { return MegBuilder(mission).build(); }

}  // namespace eamos::graph
