#include "cli/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "dex/trace_writers.h"

namespace eamos::cli {

namespace {
// Redrawn at most this often: a virtual-time run makes thousands of events a second, and a
// terminal drawing each one would be what slows the run down.
constexpr auto kRedrawEvery = std::chrono::milliseconds(100);
constexpr int kBarWidth = 20;
}  // namespace

bool stdout_is_terminal() {
  const char* term = std::getenv("TERM");
  return isatty(STDOUT_FILENO) && !(term && std::strcmp(term, "dumb") == 0);
}

namespace {

WaitGraph wait_graph(const dex::Mission& m) {
  WaitGraph g;
  std::size_t n = m.nodes.size();
  g.meg.resize(n);
  g.holder.resize(n);
  g.next.resize(n);
  g.needs.resize(n);
  g.sync.resize(n);
  g.own_before.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const dex::Node& node = m.nodes[i];
    g.meg[i] = node.meg;
    g.holder[i] = node.drone;
    if (node.internal) g.node_of[node.meg] = static_cast<int>(i);
    if (node.internal && graph::is_sync_point(node.kind) && node.waits >= 0)
      for (int other : m.drone_sets[node.waits])
        if (other != m.self) g.sync[i].push_back(other);
  }
  for (const dex::Arc& a : m.arcs) {
    if (a.kind != graph::ArcKind::exec) continue;
    const dex::Node& from = m.nodes[a.from];
    if (from.internal) g.next[a.from].push_back(a.to);
    if (from.internal && m.nodes[a.to].internal) g.own_before[a.to].push_back(a.from);
    if (!from.internal && m.nodes[a.to].internal) g.needs[a.to].push_back({from.drone, from.meg});
  }
  return g;
}

}  // namespace

ProgressDisplay::ProgressDisplay(std::ostream& out, const std::vector<dex::Mission>& missions) : out_(out) {
  for (const dex::Mission& m : missions) {
    DroneProgress d;
    d.name = m.fleet.empty() ? m.settings.name : m.fleet[m.self];
    for (const dex::Node& n : m.nodes) d.actions += n.internal && n.kind == graph::MegKind::action;
    index_[d.name] = static_cast<int>(drones_.size());
    drones_.push_back(std::move(d));
    graphs_.push_back(wait_graph(m));
  }
}

bool ProgressDisplay::pending(int self, const std::vector<int>& nodes, std::set<int>& on, std::string& until) const {
  const WaitGraph& g = graphs_[self];
  for (int next : nodes) {
    // A condition found false (its own WaitUntil, or another drone's it waits behind).
    auto c = false_conditions_.find(g.meg[next]);
    if (c != false_conditions_.end() && !ended_nodes_.count({g.holder[next], g.meg[next]})) {
      until = c->second;
      return true;
    }
    if (g.holder[next] != self) {  // another drone's node comes next (its action, its copy of a sync point)
      if (!ended_nodes_.count({g.holder[next], g.meg[next]})) on.insert(g.holder[next]);
      continue;
    }
    for (const auto& [drone, meg] : g.needs[next]) {
      if (ended_nodes_.count({drone, meg})) continue;
      auto w = false_conditions_.find(meg);
      if (w != false_conditions_.end()) {
        until = w->second;
        return true;
      }
      on.insert(drone);
    }
    for (int other : g.sync[next]) {
      // Another drone has arrived at the sync point when its own copy ended or it idles
      // right before it.
      if (ended_nodes_.count({other, g.meg[next]})) continue;
      const DroneProgress& o = drones_[other];
      bool there = false;
      if (o.running.empty() && o.last >= 0)
        for (int n : graphs_[other].next[o.last]) there |= graphs_[other].meg[n] == g.meg[next];
      if (!there) on.insert(other);
    }
  }
  return !on.empty();
}

std::string ProgressDisplay::waiting_text(const DroneProgress& d) const {
  int self = index_.at(d.name);
  const WaitGraph& g = graphs_[self];
  std::set<int> on;
  std::string until;
  // First what the last node's end lets start; when that is all done, the drone's own nodes
  // that only other drones still hold up (every own node before them has ended).
  bool found = d.last >= 0 && pending(self, g.next[d.last], on, until);
  if (!found) {
    std::vector<int> held;
    for (std::size_t n = 0; n < g.meg.size(); ++n) {
      if (g.holder[n] != self || g.needs[n].empty() || ended_nodes_.count({self, g.meg[n]})) continue;
      bool ready = true;
      for (int before : g.own_before[n]) ready &= ended_nodes_.count({self, g.meg[before]}) > 0;
      if (ready) held.push_back(static_cast<int>(n));
    }
    found = pending(self, held, on, until);
  }
  if (!until.empty()) return "waiting until " + until;
  if (on.empty()) return "waiting";
  std::string names;
  for (int i : on) names += (names.empty() ? "" : ", ") + drones_[i].name;
  return "waiting for " + names;
}

std::vector<std::string> ProgressDisplay::lines() const {
  std::vector<std::string> out;
  for (const DroneProgress& d : drones_) out.push_back(line(d));
  return out;
}

void ProgressDisplay::apply(const dex::TraceEvent& e) {
  // The ground hears events out of order; the mission's end says when it really ended.
  now_ = e.event == "mission" ? e.t : std::max(now_, e.t);
  auto it = index_.find(e.drone);
  if (it == index_.end()) return;
  DroneProgress& d = drones_[it->second];
  const WaitGraph& g = graphs_[it->second];
  auto ended = [&] {
    ended_nodes_.insert({it->second, e.node});
    false_conditions_.erase(e.node);
    auto n = g.node_of.find(e.node);
    if (n != g.node_of.end()) d.last = n->second;
  };
  if (e.event == "start") {
    d.running.push_back(e.text.empty() ? e.name : e.text);
  } else if (e.event == "end") {
    auto r = std::find(d.running.begin(), d.running.end(), e.text.empty() ? e.name : e.text);
    if (r != d.running.end()) d.running.erase(r);
    if (e.node >= 0) {
      d.done.insert(e.node);
      ended();
    }
  } else if (e.event == "node" && e.node >= 0 && (e.outcome == "ended" || e.outcome == "released")) {
    ended();
  } else if (e.event == "condition" && e.value) {
    // A condition found false holds its drone until it turns true (WaitUntil, PauseUntil).
    if (*e.value) false_conditions_.erase(e.node);
    else false_conditions_[e.node] = e.text;
  } else if (e.event == "failsafe") {
    d.failsafe = true;
    d.running.clear();
  }
}

std::string ProgressDisplay::line(const DroneProgress& d) const {
  // Done = ended at least once. A completed mission is all done: the actions of branches it
  // did not take (If, Do) will never run, and are counted as not run.
  int percent = d.actions > 0 ? static_cast<int>(100 * d.done.size() / d.actions) : 100;
  int not_run = d.actions - static_cast<int>(d.done.size());
  if (completed_) percent = 100;
  int filled = percent * kBarWidth / 100;
  std::string bar = std::string(filled, '#') + std::string(kBarWidth - filled, '.');
  std::string doing = d.failsafe          ? "failsafe"
                      : !d.running.empty() ? d.running.back()
                      : completed_ && not_run > 0 ? "done (" + std::to_string(not_run) + " not run)"
                      : ended_ ? "done"
                               : waiting_text(d);
  if (d.running.size() > 1) doing += " (+" + std::to_string(d.running.size() - 1) + ")";
  char head[96];
  std::snprintf(head, sizeof head, "%-8s [%s] %3d%%  %8.2f s  ", d.name.c_str(), bar.c_str(), percent, now_);
  return head + doing;
}

void ProgressDisplay::draw() {
  // Back to the first status line, then each line cleared and written again.
  if (drawn_ > 0) out_ << "\x1b[" << drawn_ << "F";
  for (const DroneProgress& d : drones_) out_ << "\x1b[2K" << line(d) << "\n";
  drawn_ = static_cast<int>(drones_.size());
  dirty_ = false;
  out_ << std::flush;
  last_draw_ = std::chrono::steady_clock::now();
}

void ProgressDisplay::print_above(const std::string& text) {
  if (drawn_ > 0) out_ << "\x1b[" << drawn_ << "F\x1b[J";  // up, and clear the status block
  drawn_ = 0;
  out_ << text;
  draw();
}

void ProgressDisplay::record(const dex::TraceEvent& e) {
  apply(e);
  dirty_ = true;
  // What a person must not miss stays on the screen as a line of the live log.
  bool notable = e.event == "failsafe" || e.event == "vehicle" || e.event == "error" || e.event == "conflict" ||
                 e.event == "give_way" || e.event == "resume" || (e.event == "end" && e.outcome == "failed");
  if (e.event == "mission") {
    ended_ = true;
    completed_ = e.outcome == "completed";
  }
  if (notable || e.event == "mission") {
    std::ostringstream text;
    dex::LiveLog log(text);
    log.record(e);
    print_above(text.str());
    return;
  }
  // The first draw waits for the first action, so it shows the mission under way.
  bool first = drawn_ == 0 && e.event == "start";
  if (first || (drawn_ > 0 && std::chrono::steady_clock::now() - last_draw_ >= kRedrawEvery)) draw();
}

void ProgressDisplay::finish() {
  ended_ = true;
  if (dirty_ || drawn_ == 0) draw();
}

}  // namespace eamos::cli
