#include "dex/mission.h"

#include <algorithm>

#include "dex/engine_do.h"

namespace eamos::dex {

int Mission::find(int meg, int drone) const {
  auto it = index.find(key(meg, drone));
  return it == index.end() ? -1 : it->second;
}

std::vector<int> link_mission(Mission& m) {
  std::vector<int> repeated;
  m.index.clear();
  m.index.reserve(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) {
    Node& n = m.nodes[i];
    n.out.clear();
    n.exec_in = n.back_in = 0;
    n.condition_reads.clear();
    if (n.kind == graph::MegKind::condition) collect_drones(n.condition, n.condition_reads);
    n.waits_count = 0;
    if (n.waits >= 0) {
      const std::vector<int>& set = m.drone_sets[n.waits].get();
      n.waits_count = static_cast<int>(set.size()) - (std::binary_search(set.begin(), set.end(), m.self) ? 1 : 0);
    }
    if (!m.index.emplace(Mission::key(n.meg, n.drone), static_cast<int>(i)).second)
      repeated.push_back(static_cast<int>(i));
  }
  for (std::size_t a = 0; a < m.arcs.size(); ++a) {
    const Arc& arc = m.arcs[a];
    m.nodes[arc.from].out.push_back(static_cast<int>(a));
    if (arc.kind == graph::ArcKind::exec) ++m.nodes[arc.to].exec_in;
    if (arc.kind == graph::ArcKind::back) ++m.nodes[arc.to].back_in;
  }
  return repeated;
}

long long Mission::messages_per_pass() const {
  long long pass = 0;
  const long long others = static_cast<long long>(fleet.size()) - 1;
  std::vector<int> remote;
  for (const Node& n : nodes) {
    if (n.notify >= 0) ++pass;
    if (!n.internal) continue;
    remote.clear();
    for (int a : n.out) {
      const Node& to = nodes[arcs[a].to];
      if (!to.internal && !graph::is_sync_point(to.kind) && std::find(remote.begin(), remote.end(), to.drone) == remote.end())
        remote.push_back(to.drone);
    }
    pass += static_cast<long long>(remote.size());
    if (n.kind == graph::MegKind::condition && is_do(n.control)) pass += others;
  }
  return pass;
}

}  // namespace eamos::dex
