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
    index_.resize(meg.drone_count);
    for (int d = 0; d < meg.drone_count; ++d) mdgs_[d].drone = d;
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
  static std::uint64_t key(Instance i, int drone_count) {
    return static_cast<std::uint64_t>(i.meg) * static_cast<std::uint64_t>(drone_count) + i.drone;
  }

  /// Index of instance `i` in the MDG of drone `d`, added (internal or external) if new.
  int node(int d, Instance i) {
    auto [it, fresh] = index_[d].emplace(key(i, meg_.drone_count), 0);
    if (fresh) {
      it->second = static_cast<int>(mdgs_[d].nodes.size());
      mdgs_[d].nodes.push_back({i.meg, i.drone, i.drone == d, {}});
    }
    return it->second;
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
  std::vector<std::unordered_map<std::uint64_t, int>> index_;
};

}  // namespace

std::vector<Mdg> build_mdgs(const Meg& meg) { return MdgBuilder(meg).build(); }

}  // namespace eamos::graph
