#include "graph/meg.h"

#include <algorithm>
#include <map>

namespace eamos::graph {

int Meg::add_node(MegKind kind, SourceLocation loc, int amt) {
  MegNode n;
  n.id = static_cast<int>(nodes.size());
  n.kind = kind;
  n.loc = loc;
  n.amt = amt;
  nodes.push_back(std::move(n));
  return nodes.back().id;
}

int Meg::add_arc(int from, int to, ArcKind kind, Branch branch) {
  int id = static_cast<int>(arcs.size());
  arcs.push_back({from, to, kind, branch});
  nodes[from].out.push_back(id);
  nodes[to].in.push_back(id);
  return id;
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

class MegBuilder {
 public:
  MegBuilder(const Amt& amt, const lang::Mission& m) : amt_(amt) {
    meg_.drone_count = static_cast<int>(m.drones.size());
  }

  Meg build() {
    meg_.nodes.reserve(node_bound());
    const AmtNode& root = amt_.nodes[amt_.root()];
    meg_.init = meg_.add_node(MegKind::init, root.loc, root.id);
    meg_.nodes[meg_.init].name = "INIT";
    Ends ends = build_children(root, {{meg_.init}});
    meg_.end = meg_.add_node(MegKind::end, root.loc);
    meg_.nodes[meg_.end].name = "end";
    // One drone holds the end: cloning it onto every drone would cost an arc from each
    // last node to each drone, quadratic in fleet size, for no decision anyone needs.
    meg_.nodes[meg_.end].drone = 0;
    connect(ends, meg_.end);
    return std::move(meg_);
  }

 private:
  /// At most the number of MEG nodes the AMT turns into: one per init, fork, async
  /// terminal, action and pause, up to three per control structure (its condition and two
  /// terminals), plus the end. Reserving it keeps the node vector from being copied as it
  /// grows, which at 500,000 nodes costs time and a transient third of the MEG's memory.
  std::size_t node_bound() const {
    std::size_t bound = 1;
    for (const AmtNode& n : amt_.nodes) bound += n.kind == AmtKind::seq ? 0 : n.kind == AmtKind::control ? 3 : 1;
    return bound;
  }

  void connect(const Ends& ends, int to) {
    for (const Pending& p : ends) meg_.add_arc(p.node, to, ArcKind::exec, p.branch);
  }

  /// The drone of the first action in a subtree (depth first), or -1.
  int first_action_drone(int amt_node) const {
    std::vector<int> stack{amt_node};
    while (!stack.empty()) {
      const AmtNode& n = amt_.nodes[stack.back()];
      stack.pop_back();
      if (n.kind == AmtKind::action) return n.drone;
      for (auto it = n.children.rbegin(); it != n.children.rend(); ++it) stack.push_back(*it);
    }
    return -1;
  }

  /// The drone of the nearest open end that has one, or -1.
  int drone_of(const Ends& ends) const {
    for (const Pending& p : ends)
      if (meg_.nodes[p.node].drone >= 0) return meg_.nodes[p.node].drone;
    return -1;
  }

  Ends build_children(const AmtNode& n, Ends ends) {
    for (int c : n.children) ends = build(amt_.nodes[c], ends);
    return ends;
  }

  Ends build(const AmtNode& n, const Ends& ends) {
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

  Ends build_par(const AmtNode& n, const Ends& ends) {
    int fork = meg_.add_node(MegKind::fork, n.loc, n.id);
    meg_.nodes[fork].name = n.name;
    connect(ends, fork);
    Ends out;
    for (int c : n.children) {
      Ends child = build(amt_.nodes[c], {{fork}});
      out.insert(out.end(), child.begin(), child.end());
    }
    if (n.children.empty()) out.push_back({fork});
    return out;
  }

  // async(F): F starts where the call stands; the sequence goes on from the same point,
  // and F's end goes to a terminal of its own that nothing waits for.
  Ends build_async(const AmtNode& n, const Ends& ends) {
    const AmtNode& body = amt_.nodes[n.children.at(0)];
    Ends body_ends = build(body, ends);
    int t = meg_.add_node(MegKind::terminal, n.loc, n.id);
    meg_.nodes[t].name = "async " + std::string(body.name);
    int owner = first_action_drone(body.id);
    meg_.nodes[t].drone = owner >= 0 ? owner : std::max(0, drone_of(ends));
    connect(body_ends, t);
    return ends;
  }

  Ends build_action(const AmtNode& n, const Ends& ends) {
    int a = meg_.add_node(MegKind::action, n.loc, n.id);
    MegNode& node = meg_.nodes[a];
    node.drone = n.drone;
    node.name = n.name;
    node.args = n.args;
    std::vector<int> order;
    for (const lang::Expr* e : n.args) collect_reads(e, order);
    node.reads = unique_drones(order);
    connect(ends, a);
    return {{a}};
  }

  Ends build_pause(const AmtNode& n, const Ends& ends) {
    int p = meg_.add_node(MegKind::pause, n.loc, n.id);
    int owner = drone_of(ends);
    meg_.nodes[p].drone = owner >= 0 ? owner : 0;
    meg_.nodes[p].name = n.name;
    meg_.nodes[p].seconds = n.seconds;
    connect(ends, p);
    return {{p}};
  }

  // The evaluating drone: the one the condition reads most (ties: first read), so that
  // the freshest values are local; a condition on constants goes to the first drone of
  // its branches, then to the drone that ran just before it.
  int condition_owner(const AmtNode& n, const Ends& ends, const std::vector<int>& order) const {
    std::map<int, int> count;
    for (int d : order) ++count[d];
    int best = -1, best_count = 0;
    for (int d : order)
      if (count[d] > best_count) {
        best = d;
        best_count = count[d];
      }
    if (best >= 0) return best;
    for (int c : n.children) {
      int d = first_action_drone(c);
      if (d >= 0) return d;
    }
    int d = drone_of(ends);
    return d >= 0 ? d : 0;
  }

  int add_terminal(const AmtNode& n, int condition, Role role) {
    int t = meg_.add_node(MegKind::terminal, n.loc, n.id);
    MegNode& node = meg_.nodes[t];
    node.drone = meg_.nodes[condition].drone;
    node.owner_condition = condition;
    node.role = role;
    node.name = std::string(role_name(role)) + " " + std::string(n.name);
    meg_.nodes[condition].terminals.push_back(t);
    return t;
  }

  const AmtNode* child_with_role(const AmtNode& n, Role role) const {
    for (int c : n.children)
      if (amt_.nodes[c].role == role) return &amt_.nodes[c];
    return nullptr;
  }

  /// Nodes [first, last) belong to the body of condition `c` unless a body nested inside
  /// already claimed them (inner bodies are built, and marked, first).
  void mark_scope(int first, int last, int c) {
    for (int i = first; i < last; ++i)
      if (meg_.nodes[i].scope < 0) meg_.nodes[i].scope = c;
  }

  /// Builds a branch starting at (condition, branch) and ends it in a new terminal.
  int build_branch(const AmtNode& n, int c, Role role, Branch branch) {
    const AmtNode* body = child_with_role(n, role);
    Ends body_ends = body ? build(*body, {{c, branch}}) : Ends{{c, branch}};
    int t = add_terminal(n, c, role);
    connect(body_ends, t);
    return t;
  }

  Ends build_control(const AmtNode& n, const Ends& ends) {
    int c = meg_.add_node(MegKind::condition, n.loc, n.id);
    {
      MegNode& node = meg_.nodes[c];
      node.name = n.name;
      node.control = n.control;
      node.condition = n.condition;
      node.count = n.count;
      std::vector<int> order;
      collect_reads(n.condition, order);
      node.reads = unique_drones(order);
      node.drone = condition_owner(n, ends, order);
    }
    connect(ends, c);
    switch (n.control) {
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
      case ControlKind::DoWhileAsync: return build_do(n, c, ends);
      default: return {{c}};
    }
  }

  // Do*: the do-branch runs while the condition says "do"; a flip cancels it (every node
  // built for it is in `cancels`) and starts the done-branch. The do-terminal tells the
  // condition to stop watching; the two terminals release each other so that the
  // statement after a Sync Do waits for exactly one of them.
  Ends build_do(const AmtNode& n, int c, const Ends&) {
    bool sync = n.control == ControlKind::DoUntilSync || n.control == ControlKind::DoWhileSync;
    int first = static_cast<int>(meg_.nodes.size());
    const AmtNode* body = child_with_role(n, Role::do_);
    Ends body_ends = body ? build(*body, {{c, Branch::do_}}) : Ends{{c, Branch::do_}};
    int last = static_cast<int>(meg_.nodes.size());
    for (int i = first; i < last; ++i) meg_.nodes[c].cancels.push_back(i);
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

  const Amt& amt_;
  Meg meg_;
};

}  // namespace

Meg build_meg(const Amt& amt, const lang::Mission& mission) {
  return MegBuilder(amt, mission).build();
}

}  // namespace eamos::graph
