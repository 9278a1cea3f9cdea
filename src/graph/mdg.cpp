#include "graph/mdg.h"

#include <algorithm>
#include <unordered_map>

namespace eamos::graph {

int Mdg::find(int meg, int drone) const {
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].meg == meg && nodes[i].drone == drone) return static_cast<int>(i);
  return -1;
}

std::size_t Mdg::internal_count() const {
  return static_cast<std::size_t>(
      std::count_if(nodes.begin(), nodes.end(), [](const MdgNode& n) { return n.internal; }));
}

std::vector<std::vector<int>> sync_clones(const Meg& meg) {
  std::vector<std::vector<int>> clones(meg.nodes.size());
  std::vector<char> state(meg.nodes.size(), 0);  // 0 new, 1 on stack, 2 done
  // Sync points only lead to sync points forward (no back arcs), so a post-order walk
  // computes every clone set from its successors; iterative, nesting can be deep.
  for (std::size_t root = 0; root < meg.nodes.size(); ++root) {
    if (!is_sync_point(meg.nodes[root].kind) || state[root] == 2) continue;
    std::vector<std::pair<int, std::size_t>> stack{{static_cast<int>(root), 0}};
    state[root] = 1;
    while (!stack.empty()) {
      auto& [v, next] = stack.back();
      const MegNode& n = meg.nodes[v];
      if (next < n.out.size()) {
        int to = meg.arcs[n.out[next++]].to;
        if (is_sync_point(meg.nodes[to].kind) && state[to] == 0) {
          state[to] = 1;
          stack.push_back({to, 0});
        }
        continue;
      }
      std::vector<int>& mine = clones[v];
      for (int arc : n.out) {
        int to = meg.arcs[arc].to;
        if (is_sync_point(meg.nodes[to].kind))
          mine.insert(mine.end(), clones[to].begin(), clones[to].end());
        else
          mine.push_back(meg.nodes[to].drone);
      }
      std::sort(mine.begin(), mine.end());
      mine.erase(std::unique(mine.begin(), mine.end()), mine.end());
      state[v] = 2;
      stack.pop_back();
    }
  }
  return clones;
}

namespace {

class MdgBuilder {
 public:
  explicit MdgBuilder(const Meg& meg) : meg_(meg), clones_(sync_clones(meg)) {
    mdgs_.resize(meg.drone_count);
    for (int d = 0; d < meg.drone_count; ++d) mdgs_[d].drone = d;
    first_instance_.resize(meg.nodes.size());
    int instances = 0;
    for (const MegNode& n : meg.nodes) {
      first_instance_[n.id] = instances;
      instances += is_sync_point(n.kind) ? static_cast<int>(clones_[n.id].size()) : 1;
    }
    internal_index_.assign(instances, -1);
    external_index_.resize(meg.drone_count);
  }

  std::vector<Mdg> build() {
    // Every instance a drone holds is internal to its MDG, connected or not.
    for (const MegNode& n : meg_.nodes) {
      if (is_sync_point(n.kind))
        for (int d : clones_[n.id]) node(d, {n.id, d});
      else
        node(n.drone, {n.id, n.drone});
    }
    for (const MegArc& a : meg_.arcs) expand(a);
    add_cancel_scopes();
    add_reads();
    return std::move(mdgs_);
  }

 private:
  /// Dense id of an instance: its MEG node's first id, plus the clone's position among
  /// the node's (sorted) clone holders for a sync point.
  int instance_id(Instance i) const {
    int id = first_instance_[i.meg];
    if (!is_sync_point(meg_.nodes[i.meg].kind)) return id;
    const std::vector<int>& holders = clones_[i.meg];
    return id + static_cast<int>(std::lower_bound(holders.begin(), holders.end(), i.drone) - holders.begin());
  }

  /// Index of instance `i` in the MDG of drone `d`, added (internal or external) if new.
  int node(int d, Instance i) {
    int id = instance_id(i);
    int* index = nullptr;
    if (i.drone == d) {
      index = &internal_index_[id];
    } else {
      index = &external_index_[d].emplace(id, -1).first->second;
    }
    if (*index < 0) {
      *index = static_cast<int>(mdgs_[d].nodes.size());
      mdgs_[d].nodes.push_back({i.meg, i.drone, i.drone == d, {}});
    }
    return *index;
  }

  void arc(Instance from, Instance to, const MegArc& a) {
    int df = from.drone, dt = to.drone;
    mdgs_[df].arcs.push_back({node(df, from), node(df, to), a.kind, a.branch});
    if (dt != df) mdgs_[dt].arcs.push_back({node(dt, from), node(dt, to), a.kind, a.branch});
  }

  /// The paper's forward and backward fork processing, per arc: a sync point stands for
  /// its clones, and an arc into or out of one becomes an arc per clone that needs it.
  void expand(const MegArc& a) {
    const MegNode& u = meg_.nodes[a.from];
    const MegNode& v = meg_.nodes[a.to];
    bool su = is_sync_point(u.kind), sv = is_sync_point(v.kind);
    if (!su && !sv) {
      arc({u.id, u.drone}, {v.id, v.drone}, a);
    } else if (!su && sv) {
      for (int k : clones_[v.id]) arc({u.id, u.drone}, {v.id, k}, a);
    } else if (su && !sv) {
      arc({u.id, v.drone}, {v.id, v.drone}, a);
    } else {
      for (int k : clones_[v.id]) arc({u.id, k}, {v.id, k}, a);
    }
  }

  void add_cancel_scopes() {
    for (const MegNode& c : meg_.nodes) {
      if (c.cancels.empty()) continue;
      for (int target : c.cancels) {
        const MegNode& t = meg_.nodes[target];
        std::vector<int> holders = is_sync_point(t.kind) ? clones_[t.id] : std::vector<int>{t.drone};
        for (int d : holders) {
          int cn = node(d, {c.id, c.drone});
          int tn = node(d, {t.id, d});
          mdgs_[d].nodes[cn].cancels.push_back(tn);
        }
      }
    }
  }

  void add_reads() {
    for (const MegNode& n : meg_.nodes) {
      if (n.drone < 0) continue;
      auto& reads = mdgs_[n.drone].reads;
      for (int d : n.reads)
        if (d != n.drone && std::find(reads.begin(), reads.end(), d) == reads.end()) reads.push_back(d);
    }
    for (auto& m : mdgs_) std::sort(m.reads.begin(), m.reads.end());
  }

  const Meg& meg_;
  std::vector<std::vector<int>> clones_;
  std::vector<Mdg> mdgs_;
  // Where each instance sits in the MDGs that hold it. Every instance is internal to its
  // holder's MDG, so that index is a plain array; the other drones' instances an MDG
  // holds (its external nodes) are found in a small hash map per MDG.
  std::vector<int> first_instance_;  ///< per MEG node: id of its first instance
  std::vector<int> internal_index_;  ///< per instance: index in its holder's MDG, -1 not yet
  std::vector<std::unordered_map<int, int>> external_index_;  ///< per MDG: instance → index
};

}  // namespace

std::vector<Mdg> build_mdgs(const Meg& meg) { return MdgBuilder(meg).build(); }

}  // namespace eamos::graph
