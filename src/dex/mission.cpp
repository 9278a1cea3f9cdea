#include "dex/mission.h"

#include <algorithm>

#include "dex/engine_do.h"

namespace eamos::dex {

int Mission::find(int meg, int drone) const {
  auto it = index.find(key(meg, drone));
  return it == index.end() ? -1 : it->second;
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
