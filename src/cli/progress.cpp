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

ProgressDisplay::ProgressDisplay(std::ostream& out, const std::vector<dex::Mission>& missions) : out_(out) {
  for (const dex::Mission& m : missions) {
    DroneProgress d;
    d.name = m.fleet.empty() ? m.settings.name : m.fleet[m.self];
    for (const dex::Node& n : m.nodes) d.actions += n.internal && n.kind == graph::MegKind::action;
    index_[d.name] = static_cast<int>(drones_.size());
    drones_.push_back(std::move(d));
  }
}

void ProgressDisplay::apply(const dex::TraceEvent& e) {
  // The ground hears events out of order; the mission's end says when it really ended.
  now_ = e.event == "mission" ? e.t : std::max(now_, e.t);
  auto it = index_.find(e.drone);
  if (it == index_.end()) return;
  DroneProgress& d = drones_[it->second];
  if (e.event == "start") {
    d.running.push_back(e.text.empty() ? e.name : e.text);
  } else if (e.event == "end") {
    auto r = std::find(d.running.begin(), d.running.end(), e.text.empty() ? e.name : e.text);
    if (r != d.running.end()) d.running.erase(r);
    if (e.node >= 0) d.done.insert(e.node);
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
                               : "waiting";
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
  bool notable = e.event == "failsafe" || e.event == "vehicle" || e.event == "error" ||
                 (e.event == "end" && e.outcome == "failed");
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
