#include "graph/mdg.h"

#include <algorithm>
#include <map>

namespace eamos::graph {

int Mdg::find(int meg, int drone) const {
  for (std::size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].meg == meg && nodes[i].drone == drone) return static_cast<int>(i);
  return -1;
}

std::span<const int> Mdg::cancels(int node) const {
  int list = nodes[node].cancels;
  if (list < 0) return {};
  return cancel_lists[list];
}

std::vector<int>& Mdg::cancel_list(int node) {
  int& list = nodes[node].cancels;
  if (list < 0) {
    list = static_cast<int>(cancel_lists.size());
    cancel_lists.emplace_back();
  }
  return cancel_lists[list];
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
      std::span<const int> out = meg.out(v);
      if (next < out.size()) {
        int to = meg.arcs[out[next++]].to;
        if (is_sync_point(meg.nodes[to].kind) && state[to] == 0) {
          state[to] = 1;
          stack.push_back({to, 0});
        }
        continue;
      }
      std::vector<int>& mine = clones[v];
      for (int arc : out) {
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

std::vector<std::pair<int, int>> drone_ranges(const std::vector<int>& set) {
  std::vector<std::pair<int, int>> ranges;
  for (int d : set) {
    if (!ranges.empty() && ranges.back().second + 1 == d) ranges.back().second = d;
    else ranges.push_back({d, d});
  }
  return ranges;
}

std::vector<std::vector<int>> sync_arrivers(const Meg& meg) {
  std::vector<std::vector<int>> arrivers(meg.nodes.size());
  for (const MegArc& a : meg.arcs) {
    const MegNode& u = meg.nodes[a.from];
    if (is_sync_point(meg.nodes[a.to].kind) && !is_sync_point(u.kind)) arrivers[a.to].push_back(u.drone);
  }
  for (auto& set : arrivers) {
    std::sort(set.begin(), set.end());
    set.erase(std::unique(set.begin(), set.end()), set.end());
  }
  return arrivers;
}

namespace {

/// A map from a pair of non-negative ints to an int, open addressing in one array: the
/// builder finds millions of (drone, instance) pairs, and a node-based hash map per drone
/// cost an allocation per entry and, freeing them, a tenth of a cross-squad compile.
class PairIndex {
 public:
  /// The value of (a, b), inserted as `fresh` when missing; the pointer is valid until the
  /// next insertion.
  int* emplace(int a, int b, int fresh) {
    if (2 * (used_ + 1) > slots_.size()) grow();
    unsigned long long key = pack(a, b);
    for (std::size_t i = slot_of(key);; i = (i + 1) & (slots_.size() - 1)) {
      Slot& s = slots_[i];
      if (s.key == key) return &s.value;
      if (s.key == kEmpty) {
        s = {key, fresh};
        ++used_;
        return &s.value;
      }
    }
  }

 private:
  static constexpr unsigned long long kEmpty = ~0ULL;
  struct Slot {
    unsigned long long key = kEmpty;
    int value = 0;
  };

  static unsigned long long pack(int a, int b) {
    return static_cast<unsigned long long>(static_cast<unsigned>(a)) << 32 | static_cast<unsigned>(b);
  }
  std::size_t slot_of(unsigned long long key) const {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ULL) >> shift_);
  }

  void grow() {
    std::vector<Slot> old;
    old.swap(slots_);
    std::size_t size = old.empty() ? 1024 : old.size() * 2;
    slots_.assign(size, Slot{});
    shift_ = 64;
    for (std::size_t n = size; n > 1; n >>= 1) --shift_;
    for (const Slot& s : old)
      if (s.key != kEmpty)
        for (std::size_t i = slot_of(s.key);; i = (i + 1) & (size - 1))
          if (slots_[i].key == kEmpty) {
            slots_[i] = s;
            break;
          }
  }

  std::vector<Slot> slots_;  ///< a power of two long, at most half full
  std::size_t used_ = 0;
  int shift_ = 64;
};

class MdgBuilder {
 public:
  explicit MdgBuilder(const Meg& meg) : meg_(meg), clones_(sync_clones(meg)), arrivers_(sync_arrivers(meg)) {
    mdgs_.resize(meg.drone_count);
    for (int d = 0; d < meg.drone_count; ++d) mdgs_[d].drone = d;
    first_instance_.resize(meg.nodes.size());
    int instances = 0;
    for (const MegNode& n : meg.nodes) {
      first_instance_[n.id] = instances;
      instances += is_sync_point(n.kind) ? static_cast<int>(clones_[n.id].size()) : 1;
    }
    internal_index_.assign(instances, -1);
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
    add_barrier_waits();
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
      index = external_index_.emplace(d, id, -1);
    }
    if (*index < 0) {
      *index = static_cast<int>(mdgs_[d].nodes.size());
      mdgs_[d].nodes.push_back({.meg = i.meg, .drone = i.drone, .internal = i.drone == d});
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
      arrival_arc(u, v, a);
    } else if (su && !sv) {
      arc({u.id, v.drone}, {v.id, v.drone}, a);
    } else {
      for (int k : clones_[v.id]) arc({u.id, k}, {v.id, k}, a);
    }
  }

  /// An arc from a drone's own node into a sync point stays on that drone: into its own
  /// clone if it holds one, else into one external copy. Either announces the drone's
  /// arrival to the other holders once all of the drone's arcs into it have fired.
  void arrival_arc(const MegNode& u, const MegNode& s, const MegArc& a) {
    const std::vector<int>& holders = clones_[s.id];
    int d = u.drone;
    bool holds = std::binary_search(holders.begin(), holders.end(), d);
    int to = node(d, {s.id, holds ? d : holders.front()});
    Mdg& g = mdgs_[d];
    g.arcs.push_back({node(d, {u.id, d}), to, a.kind, a.branch});
    if (holders.size() > (holds ? 1u : 0u)) g.nodes[to].notify = drone_set(d, global_set(holders_set_, s.id, holders));
  }

  /// Each clone waits for the arrival of every drone whose work leads into it.
  void add_barrier_waits() {
    for (const MegNode& n : meg_.nodes) {
      if (!is_sync_point(n.kind)) continue;
      const std::vector<int>& arrivers = arrivers_[n.id];
      for (int d : clones_[n.id]) {
        bool self_only = arrivers.size() == 1 && arrivers.front() == d;
        if (arrivers.empty() || self_only) continue;
        mdgs_[d].nodes[node(d, {n.id, d})].waits = drone_set(d, global_set(arrivers_set_, n.id, arrivers));
      }
    }
  }

  /// The global id of a sync point's set, looked up once per sync point (`cache`), so a
  /// barrier of k drones compares its set once, not once per arc.
  int global_set(std::vector<int>& cache, int meg, const std::vector<int>& set) {
    if (cache.empty()) cache.assign(meg_.nodes.size(), -1);
    if (cache[meg] < 0) {
      auto [it, added] = global_ids_.emplace(set, static_cast<int>(global_sets_.size()));
      if (added) global_sets_.push_back(&it->first);
      cache[meg] = it->second;
    }
    return cache[meg];
  }

  /// Index of global set `global` in the table of drone `d`'s MDG, added if new: a
  /// fleet-wide barrier costs one table entry per MDG, however many sync points share it.
  int drone_set(int d, int global) {
    int next = static_cast<int>(mdgs_[d].drone_sets.size());
    int index = *set_index_.emplace(d, global, next);
    if (index == next) mdgs_[d].drone_sets.push_back(*global_sets_[global]);
    return index;
  }

  void add_cancel_scopes() {
    for (const MegNode& c : meg_.nodes) {
      for (int target : meg_.cancels(c.id)) {
        const MegNode& t = meg_.nodes[target];
        std::vector<int> holders = is_sync_point(t.kind) ? clones_[t.id] : std::vector<int>{t.drone};
        for (int d : holders) {
          int cn = node(d, {c.id, c.drone});
          int tn = node(d, {t.id, d});
          mdgs_[d].cancel_list(cn).push_back(tn);
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
  std::vector<std::vector<int>> arrivers_;
  std::vector<Mdg> mdgs_;
  std::map<std::vector<int>, int> global_ids_;      ///< every drone set → its global id
  std::vector<const std::vector<int>*> global_sets_;  ///< global id → the set (keys of global_ids_)
  std::vector<int> holders_set_;   ///< per MEG node: global id of its clone holders, -1 not yet
  std::vector<int> arrivers_set_;  ///< per MEG node: global id of its arrivers, -1 not yet
  PairIndex set_index_;  ///< (drone, global set id) → the set's index in the drone's MDG
  // Where each instance sits in the MDGs that hold it. Every instance is internal to its
  // holder's MDG, so that index is a plain array; the other drones' instances an MDG
  // holds (its external nodes) are found in one hash table for every MDG.
  std::vector<int> first_instance_;  ///< per MEG node: id of its first instance
  std::vector<int> internal_index_;  ///< per instance: index in its holder's MDG, -1 not yet
  PairIndex external_index_;  ///< (drone, instance) → index in the drone's MDG
};

}  // namespace

std::vector<Mdg> build_mdgs(const Meg& meg) { return MdgBuilder(meg).build(); }

}  // namespace eamos::graph
