#include "graph/amt.h"

namespace eamos::graph {

const char* amt_kind_name(AmtKind k) {
  switch (k) {
    case AmtKind::init: return "init";
    case AmtKind::seq: return "seq";
    case AmtKind::par: return "par";
    case AmtKind::async: return "async";
    case AmtKind::control: return "control";
    case AmtKind::action: return "action";
    case AmtKind::pause: return "pause";
  }
  return "";
}

const char* role_name(Role r) {
  switch (r) {
    case Role::none: return "";
    case Role::then_: return "then";
    case Role::else_: return "else";
    case Role::wait: return "wait";
    case Role::repeat: return "repeat";
    case Role::after: return "after";
    case Role::do_: return "do";
    case Role::done: return "done";
  }
  return "";
}

std::span<const Role> branch_roles(lang::ControlKind k) {
  using lang::ControlKind;
  static constexpr Role if_roles[] = {Role::then_, Role::else_};
  static constexpr Role wait_roles[] = {Role::wait};
  static constexpr Role repeat_roles[] = {Role::repeat, Role::after};
  static constexpr Role do_roles[] = {Role::do_, Role::done};
  switch (k) {
    case ControlKind::If: return if_roles;
    case ControlKind::WaitUntil:
    case ControlKind::WaitWhile: return wait_roles;
    case ControlKind::RepeatUntil:
    case ControlKind::RepeatWhile:
    case ControlKind::RepeatFor: return repeat_roles;
    case ControlKind::DoUntilAsync:
    case ControlKind::DoWhileAsync:
    case ControlKind::DoUntilSync:
    case ControlKind::DoWhileSync: return do_roles;
    default: return {};
  }
}

namespace {

using lang::ControlKind;

class AmtBuilder {
 public:
  explicit AmtBuilder(const lang::Mission& m) : m_(m), block_sizes_(m.functions.size(), 0) {}

  Amt build() {
    const lang::Function& init = m_.functions[m_.init_function];
    amt_.nodes.reserve(block_size(m_.init_function));
    int root = add(AmtKind::init, init.loc, init.name, -1);
    expand_body(root, init);
    return std::move(amt_);
  }

 private:
  /// At most the nodes that expanding function `f` adds (its own node and everything
  /// below it). Reserving them up front keeps the node vector from being copied as it
  /// grows, which at 500,000 nodes costs time and a transient half of the AMT's memory.
  std::size_t block_size(int f) {
    if (block_sizes_[f] == 0) {
      std::size_t size = 1;
      for (const auto& s : m_.functions[f].body) size += statement_size(s);
      block_sizes_[f] = size;
    }
    return block_sizes_[f];
  }

  std::size_t statement_size(const lang::Statement& s) {
    switch (s.kind) {
      case lang::StatementKind::action: return 1;
      case lang::StatementKind::async_call: return 1 + block_size(s.function_index);
      case lang::StatementKind::call: break;
    }
    if (s.control == ControlKind::none) return block_size(s.function_index);
    std::size_t size = 1;
    for (int branch : s.branch_functions)
      if (branch >= 0) size += block_size(branch);
    return size;
  }

  int add(AmtKind kind, SourceLocation loc, std::string_view name, int parent) {
    AmtNode n;
    n.id = static_cast<int>(amt_.nodes.size());
    n.kind = kind;
    n.loc = loc;
    n.name = name;
    n.parent = parent;
    if (parent >= 0) amt_.nodes[parent].children.push_back(n.id);
    amt_.nodes.push_back(std::move(n));
    return amt_.nodes.back().id;
  }

  void expand_body(int parent, const lang::Function& f) {
    for (const auto& s : f.body) expand_statement(parent, s);
  }

  int expand_block(int parent, int function, SourceLocation call_loc) {
    const lang::Function& f = m_.functions[function];
    AmtKind kind = f.block == lang::BlockKind::par ? AmtKind::par : AmtKind::seq;
    int id = add(kind, call_loc, f.name, parent);
    expand_body(id, f);
    return id;
  }

  void expand_statement(int parent, const lang::Statement& s) {
    switch (s.kind) {
      case lang::StatementKind::action: {
        int id = add(AmtKind::action, s.loc, s.callee, parent);
        amt_.nodes[id].drone = s.drone_index;
        amt_.nodes[id].args.assign(s.args.begin(), s.args.end());
        return;
      }
      case lang::StatementKind::async_call: {
        int id = add(AmtKind::async, s.loc, "async", parent);
        expand_block(id, s.function_index, s.callee_loc);
        return;
      }
      case lang::StatementKind::call:
        if (s.control == ControlKind::none) {
          expand_block(parent, s.function_index, s.loc);
          return;
        }
        expand_control(parent, s);
        return;
    }
  }

  void expand_control(int parent, const lang::Statement& s) {
    if (s.control == ControlKind::PauseFor) {
      int id = add(AmtKind::pause, s.loc, "PauseFor", parent);
      amt_.nodes[id].seconds = s.args[0]->number;
      return;
    }
    int id = add(AmtKind::control, s.loc, lang::control_name(s.control), parent);
    amt_.nodes[id].control = s.control;
    amt_.nodes[id].condition = s.args[0];
    if (s.control == ControlKind::RepeatFor)
      amt_.nodes[id].count = static_cast<long long>(s.args[3]->number);
    std::span<const Role> roles = branch_roles(s.control);
    // Branch arguments follow the condition: args[1], args[2].
    for (std::size_t b = 0; b < roles.size() && b < s.branch_functions.size(); ++b) {
      int child = expand_block(id, s.branch_functions[b], s.args[b + 1]->loc);
      amt_.nodes[child].role = roles[b];
    }
  }

  const lang::Mission& m_;
  std::vector<std::size_t> block_sizes_;  ///< per function, 0 until computed
  Amt amt_;
};

}  // namespace

Amt build_amt(const lang::Mission& mission) { return AmtBuilder(mission).build(); }

}  // namespace eamos::graph
