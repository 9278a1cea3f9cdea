#pragma once
// Small helpers for graph tests: compile mission text, find nodes by their label.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "graph/export.h"
#include "graph/pipeline.h"

namespace eamos::test {

inline std::unique_ptr<graph::Compilation> compile_text(const std::string& text,
                                                        std::string* diagnostics = nullptr) {
  auto c = std::make_unique<graph::Compilation>();
  Diagnostics diags;
  bool ok = graph::compile(std::make_shared<SourceFile>("test.eamos", text), fleet::Fleet{}, diags, *c);
  if (diagnostics) *diagnostics = diags.format();
  if (!ok) {
    ADD_FAILURE() << "mission did not compile:\n" << diags.format();
    return nullptr;
  }
  return c;
}

/// The MEG node whose label (meg_node_label) equals `label`; -1 when none or several.
inline int node(const graph::Compilation& c, const std::string& label) {
  int found = -1;
  for (const auto& n : c.meg.nodes)
    if (graph::meg_node_label(c, n) == label) {
      if (found >= 0) return -1;
      found = n.id;
    }
  return found;
}

inline bool has_arc(const graph::Compilation& c, int from, int to,
                    graph::ArcKind kind = graph::ArcKind::exec,
                    graph::Branch branch = graph::Branch::any) {
  for (const auto& a : c.meg.arcs)
    if (a.from == from && a.to == to && a.kind == kind && a.branch == branch) return true;
  return false;
}

inline int in_degree(const graph::Compilation& c, int node, graph::ArcKind kind = graph::ArcKind::exec) {
  int n = 0;
  for (int a : c.meg.in(node)) n += c.meg.arcs[a].kind == kind ? 1 : 0;
  return n;
}

}  // namespace eamos::test
