// Separation kept in flight, in one process on the simulator: drones whose courses would
// bring them closer than the fleet's min_separation give way (hold, then fly on), and a
// give-way that cannot clear ends in the failsafe, never in a collision.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <sstream>

#include "trace/plot.h"
#include "dex/separation.h"
#include "trace/trace_schema.h"
#include "dex/flight.h"

namespace eamos::test {
namespace {

fleet::Fleet fleet_of(const std::string& yaml) {
  fleet::Fleet f;
  Diagnostics diags;
  EXPECT_TRUE(fleet::parse_fleet(std::make_shared<SourceFile>("f.yaml", yaml), f, diags)) << diags.format();
  return f;
}

/// Flies with telemetry in the trace at the simulator's own rate, so every step of every
/// drone is there to measure.
Flight fly_sampled(const std::string& text, const fleet::Fleet& fleet) {
  Flight f;
  std::vector<dex::Mission> missions = missions_of(text, fleet);
  if (missions.empty()) return f;
  mid::AdapterRegistry adapters;
  sim::register_adapter(adapters);
  dex::MemoryTrace memory;
  std::ostringstream out;
  dex::JsonlTrace jsonl(out, missions[0].fleet);
  dex::TeeTrace tee;
  tee.add(&memory);
  tee.add(&jsonl);
  dex::RunOptions options;
  options.time_limit_s = 600;
  options.telemetry_hz = 20;
  f.result = dex::run_in_process(missions, adapters, &tee, options);
  f.events = memory.events;
  f.jsonl = out.str();
  return f;
}

struct Closest {
  double horizontal = 1e9;  ///< of the pair that came nearest while too close vertically
  bool lost = false;        ///< some pair was too close both ways at once
  std::string pair;
};

/// The closest any two airborne drones came, from the trace's telemetry (every drone at
/// every tick: a sample is left out only when nothing changed).
Closest closest(const Flight& f, const fleet::Separation& min = {}) {
  std::map<std::string, mid::DroneState> last;
  Closest c;
  auto measure = [&] {
    for (auto a = last.begin(); a != last.end(); ++a)
      for (auto b = std::next(a); b != last.end(); ++b) {
        if (a->second.landed || b->second.landed) continue;
        double h = std::hypot(a->second.x - b->second.x, a->second.y - b->second.y);
        double v = std::fabs(a->second.z - b->second.z);
        if (v >= min.vertical_m) continue;
        if (h < c.horizontal) c.horizontal = h, c.pair = a->first + "/" + b->first;
        if (h < min.horizontal_m) c.lost = true;
      }
  };
  double t = -1;
  for (const dex::TraceEvent& e : f.events) {
    if (e.event != "telemetry" || !e.state) continue;
    if (e.t != t) measure();
    t = e.t;
    last[e.drone] = *e.state;
  }
  measure();
  return c;
}

int count(const Flight& f, const std::string& event, const std::string& drone = "") {
  int n = 0;
  for (const dex::TraceEvent& e : f.events) n += e.event == event && (drone.empty() || e.drone == drone);
  return n;
}

const dex::TraceEvent* first(const Flight& f, const std::string& event) {
  for (const dex::TraceEvent& e : f.events)
    if (e.event == event) return &e;
  return nullptr;
}

/// How far `drone` was from `from` at its first `event`, from the trace's telemetry.
double flown_before(const Flight& f, const std::string& event, const std::string& drone, fleet::Vec3 from) {
  std::optional<mid::DroneState> last;
  for (const dex::TraceEvent& e : f.events) {
    if (e.drone != drone) continue;
    if (e.event == "telemetry" && e.state) last = *e.state;
    if (e.event == event && last) return std::hypot(last->x - from.x, last->y - from.y, last->z - from.z);
  }
  return 1e9;
}

void expect_valid_trace(const Flight& f) {
  std::istringstream in(f.jsonl);
  // The test's trace has no header line: check the events alone, after one of our own.
  std::string header =
      R"({"t":0,"event":"header","schema":"eamos-trace","version":1,"mission":"t","mission_hash":"h","source":"t.eamos","fleet":"f.yaml","telemetry_hz":20,"drones":[)";
  std::vector<std::string> names;
  for (const auto& d : f.result.drones) names.push_back(d.name);
  for (std::size_t i = 0; i < names.size(); ++i)
    header += std::string(i ? "," : "") + R"({"name":")" + names[i] + R"(","index":)" + std::to_string(i) +
              R"(,"type":"Quad","home":[0,0,0]})";
  header += "]}\n";
  std::istringstream whole(header + f.jsonl);
  std::vector<std::string> errors = trace::check_trace(whole, {.strict = true});
  EXPECT_TRUE(errors.empty()) << errors.front();
}

const char* kTwo = "var A Quad\nvar B Quad\nfunc INIT() { PAR_go() }\nfunc PAR_go() { SEQ_a(); SEQ_b() }\n";
const char* kThree =
    "var A Quad\nvar B Quad\nvar C Quad\nfunc INIT() { PAR_go() }\nfunc PAR_go() { SEQ_a(); SEQ_b(); SEQ_c() }\n";

std::string crossing(const std::string& a, const std::string& b) {
  return std::string(kTwo) + "func SEQ_a() { A.Arm(); A.Takeoff(5); A.FlyTo(" + a + ", 0, 5); A.Land(); A.Disarm() }\n" +
         "func SEQ_b() { B.Arm(); B.Takeoff(5); B.FlyTo(0, " + b + ", 5); B.Land(); B.Disarm() }\n";
}

const char* kCrossingFleet = "drones:\n  A: {home: [-30, 0, 0]}\n  B: {home: [0, -30, 0]}\n";

TEST(Separation, CrossingPathsTheLaterDeclaredDroneGivesWayAndBothComplete) {
  Flight f = fly_sampled(crossing("30", "30"), fleet_of(kCrossingFleet));
  ASSERT_TRUE(f.result.completed) << f.result.error;
  Closest c = closest(f);
  EXPECT_FALSE(c.lost) << c.pair << " came within " << c.horizontal << " m";
  EXPECT_EQ(count(f, "give_way", "B"), 1);
  EXPECT_EQ(count(f, "give_way", "A"), 0);
  EXPECT_EQ(count(f, "resume", "B"), 1);
  const dex::TraceEvent* g = first(f, "give_way");
  ASSERT_NE(g, nullptr);
  EXPECT_EQ(g->other, "A");
  ASSERT_TRUE(g->distance.has_value());
  EXPECT_GT(*g->distance, 2.0);
  EXPECT_NE(f.jsonl.find(R"("event":"give_way")"), std::string::npos);
  EXPECT_NE(f.jsonl.find(R"("other":"A")"), std::string::npos);
  expect_valid_trace(f);
  // The plot rings where B gave way and dots where it flew on.
  std::string svg = trace::plot_svg(f.result, f.events);
  EXPECT_NE(svg.find(R"(<circle class="give-way" data-drone="B" data-other="A")"), std::string::npos);
  EXPECT_NE(svg.find(R"(<circle class="resume" data-drone="B" data-other="A")"), std::string::npos);
}

TEST(Separation, APriorityInTheFleetFileDecidesWhoGivesWay) {
  Flight f = fly_sampled(crossing("30", "30"),
                         fleet_of("drones:\n  A: {home: [-30, 0, 0]}\n  B: {home: [0, -30, 0], priority: 1}\n"
                                  "  # A ranks 1 by its place too: a tie goes to the drone declared first\n"));
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(count(f, "give_way", "B"), 1);
  Flight g = fly_sampled(crossing("30", "30"),
                         fleet_of("drones:\n  A: {home: [-30, 0, 0], priority: 5}\n  B: {home: [0, -30, 0]}\n"));
  ASSERT_TRUE(g.result.completed) << g.result.error;
  EXPECT_EQ(count(g, "give_way", "A"), 1);
  EXPECT_EQ(count(g, "give_way", "B"), 0);
  EXPECT_FALSE(closest(g).lost);
}

TEST(Separation, HeadOnSwapEndsInTheFailsafeApartWithTheReason) {
  std::string text = std::string(kTwo) +
                     "func SEQ_a() { A.Arm(); A.Takeoff(5); A.FlyTo(20, 0, 5); A.Land(); A.Disarm() }\n"
                     "func SEQ_b() { B.Arm(); B.Takeoff(5); B.FlyTo(-20, 0, 5); B.Land(); B.Disarm() }\n";
  Flight f = fly_sampled(text, fleet_of("drones:\n  A: {home: [-20, 0, 0]}\n  B: {home: [20, 0, 0]}\n"));
  ASSERT_FALSE(f.result.completed);
  EXPECT_NE(f.result.error.find("give way to each other"), std::string::npos) << f.result.error;
  EXPECT_FALSE(closest(f).lost);
  EXPECT_GE(count(f, "give_way"), 2);
  EXPECT_EQ(count(f, "failsafe"), 2);
  for (const auto& d : f.result.drones) EXPECT_TRUE(d.state.landed) << d.name;
}

std::string hover_on_path(double hover_s) {
  return std::string(kTwo) + "func SEQ_a() { A.Arm(); A.Takeoff(5); A.FlyTo(30, 0, 5); A.Land(); A.Disarm() }\n" +
         "func SEQ_b() { B.Arm(); B.Takeoff(5); B.Hover(" + std::to_string(hover_s) +
         "); B.FlyTo(0, 15, 5); B.Land(); B.Disarm() }\n";
}

TEST(Separation, ADroneHoveringOnAnothersPathIsWaitedForPastTheDeadline) {
  // A's FlyTo of 60 m may take 1.5 × 6 s + 10 s = 19 s; it waits 20 s and more for B.
  Flight f = fly_sampled(hover_on_path(25), fleet_of("drones:\n  A: {home: [-30, 0, 0]}\n  B: {home: [0, 0, 0]}\n"));
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_FALSE(closest(f).lost);
  EXPECT_EQ(count(f, "give_way", "A"), 1);
  EXPECT_EQ(count(f, "resume", "A"), 1);
  double held = 0, gave = 0;
  for (const auto& e : f.events) {
    if (e.event == "give_way") gave = e.t;
    if (e.event == "resume") held = e.t - gave;
  }
  EXPECT_GT(held, 19.0);
}

TEST(Separation, AGiveWayLongerThanItsBoundEndsInTheFailsafe) {
  Flight f = fly_sampled(hover_on_path(60), fleet_of("drones:\n  A: {home: [-30, 0, 0]}\n  B: {home: [0, 0, 0]}\n"));
  ASSERT_FALSE(f.result.completed);
  EXPECT_NE(f.result.error.find("A gave way to B for 30.0 s"), std::string::npos) << f.result.error;
  EXPECT_FALSE(closest(f).lost);
  EXPECT_EQ(count(f, "failsafe"), 2);
}

TEST(Separation, ThreeConvergingDronesPassOneAtATime) {
  std::string text = std::string(kThree) +
                     "func SEQ_a() { A.Arm(); A.Takeoff(5); A.FlyTo(30, 0, 5); A.Land(); A.Disarm() }\n"
                     "func SEQ_b() { B.Arm(); B.Takeoff(5); B.FlyTo(0, 30, 5); B.Land(); B.Disarm() }\n"
                     "func SEQ_c() { C.Arm(); C.Takeoff(5); C.FlyTo(21, 21, 5); C.Land(); C.Disarm() }\n";
  Flight f = fly_sampled(
      text, fleet_of("drones:\n  A: {home: [-30, 0, 0]}\n  B: {home: [0, -30, 0]}\n  C: {home: [-21, -21, 0]}\n"));
  ASSERT_TRUE(f.result.completed) << f.result.error;
  Closest c = closest(f);
  EXPECT_FALSE(c.lost) << c.pair << " came within " << c.horizontal << " m";
  EXPECT_EQ(count(f, "give_way", "A"), 0);
  EXPECT_GE(count(f, "give_way", "B") + count(f, "give_way", "C"), 2);
  EXPECT_EQ(count(f, "give_way"), count(f, "resume"));
}

TEST(Separation, AWiderMinSeparationFromTheFleetIsKept) {
  Flight f = fly_sampled(crossing("30", "30"),
                         fleet_of(std::string(kCrossingFleet) + "safety:\n  min_separation: {horizontal: 8, vertical: 2}\n"));
  ASSERT_TRUE(f.result.completed) << f.result.error;
  fleet::Separation wide{8, 2};
  Closest c = closest(f, wide);
  EXPECT_FALSE(c.lost) << c.pair << " came within " << c.horizontal << " m";
  EXPECT_GE(c.horizontal, 8.0);
}

TEST(Separation, DronesOnSeparateCoursesNeverGiveWay) {
  Flight f = fly_sampled(crossing("30", "-40"), fleet_of("drones:\n  A: {home: [-30, 0, 0]}\n  B: {home: [10, -30, 0]}\n"));
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(count(f, "conflict"), 0);
}

// Both hover close to where their courses cross and set off at once: from their first samples,
// standing or slow, nothing seems to come, and by the time their speeds show it, braking is too
// late. Along their goals, at the speed they are about to fly, B sees it before either moves.
TEST(Separation, TwoDronesSettingOffFromAStopOnCrossingCoursesGiveWayBeforeEitherMoves) {
  for (const char* near : {"6", "8", "10"}) {
    const std::string home = std::string("-") + near;
    Flight f = fly_sampled(crossing(near, near), fleet_of("drones:\n  A: {home: [" + home + ", 0, 0]}\n  B: {home: [0, " +
                                                           home + ", 0]}\n"));
    ASSERT_TRUE(f.result.completed) << near << ": " << f.result.error;
    Closest c = closest(f);
    EXPECT_FALSE(c.lost) << near << " m short: " << c.pair << " came within " << c.horizontal << " m";
    EXPECT_EQ(count(f, "give_way"), 1) << near;
    EXPECT_EQ(count(f, "resume"), 1) << near;
    // 6 m short, the conflict is less than kLastMomentS away when they set off: whoever looks
    // first gives way; further out, the lower priority does.
    if (std::string(near) == "6") continue;
    EXPECT_EQ(count(f, "give_way", "B"), 1) << near;
    // B sees the conflict before it has moved: from its samples alone it would see it only
    // once its speed shows, half a metre or more on.
    EXPECT_LT(flown_before(f, "give_way", "B", {0, -std::stod(near), 5}), 0.2) << near;
  }
}

// A flies straight at B, which hovers, and stops 6 m short of it: its course ends at its goal,
// so nothing gives way (a course run on past the goal would hold A for ever, then fail over).
TEST(Separation, ADroneThatStopsShortOfAHoveringOneDoesNotGiveWay) {
  std::string text = std::string(kTwo) +
                     "func SEQ_a() { A.Arm(); A.Takeoff(5); A.FlyTo(-6, 0, 5); A.Land(); A.Disarm() }\n"
                     "func SEQ_b() { B.Arm(); B.Takeoff(5); B.Hover(20); B.Land(); B.Disarm() }\n";
  Flight f = fly_sampled(text, fleet_of("drones:\n  A: {home: [-30, 0, 0]}\n  B: {home: [0, 0, 0]}\n"));
  ASSERT_TRUE(f.result.completed) << f.result.error;
  EXPECT_EQ(count(f, "give_way"), 0);
  EXPECT_FALSE(closest(f).lost);
}

TEST(SeparationPrediction, ACourseThatEndsShortOfTheOtherIsNoConflict) {
  fleet::Separation min;  // 2 m, 1 m
  // 5 m/s toward a drone 20 m away: a conflict in 3 s if it flew on, none if it stops at 10 m.
  EXPECT_TRUE(dex::predict_to_goal({0, 0, 5}, {5, 0, 0}, NAN, {20, 0, 5}, {}, min, 4.0).conflict);
  EXPECT_FALSE(dex::predict_to_goal({0, 0, 5}, {5, 0, 0}, 10.0, {20, 0, 5}, {}, min, 4.0).conflict);
  // The other drone comes to the goal while it waits there: still a conflict, after the stop.
  dex::Prediction p = dex::predict_to_goal({0, 0, 5}, {5, 0, 0}, 10.0, {20, 0, 5}, {-4, 0, 0}, min, 4.0);
  EXPECT_TRUE(p.conflict);
  EXPECT_GE(p.in_s, 2.0);
}

TEST(SeparationPrediction, CoursesThatMeetWithinTheHorizonAreAConflict) {
  fleet::Separation min;
  // Head-on at 10 m/s each, 30 m apart: within 2 m after 1.4 s.
  dex::Prediction p = dex::predict({0, 0, 5}, {10, 0, 0}, {30, 0, 5}, {-10, 0, 0}, min, 3.0);
  EXPECT_TRUE(p.conflict);
  EXPECT_NEAR(p.in_s, 1.4, 1e-9);
  // The same 1 m apart vertically is apart.
  EXPECT_FALSE(dex::predict({0, 0, 5}, {10, 0, 0}, {30, 0, 6}, {-10, 0, 0}, min, 3.0).conflict);
  // Beyond the horizon.
  EXPECT_FALSE(dex::predict({0, 0, 5}, {10, 0, 0}, {90, 0, 5}, {-10, 0, 0}, min, 3.0).conflict);
  // Already too close, but parting: holding would not help.
  EXPECT_FALSE(dex::predict({0, 0, 5}, {-1, 0, 0}, {1, 0, 5}, {1, 0, 0}, min, 3.0).conflict);
}

// A guard over drones named A, B, C…: A flown here (a simulator drone standing by, so a
// conflict of its own is recorded as one it cannot hold for), the others flown elsewhere, all
// fed telemetry samples by hand on virtual time: what the guard makes of the samples alone.
struct Guarded {
  mid::EventLoop loop;
  mid::AdapterRegistry adapters;
  std::unique_ptr<mid::Drone> a;
  dex::Mission mission;
  dex::MemoryTrace trace;
  std::unique_ptr<dex::SeparationGuard> guard;

  explicit Guarded(int drones) {
    sim::register_adapter(adapters);
    std::vector<std::string> names;
    for (int i = 0; i < drones; ++i) names.push_back(i < 26 ? std::string(1, char('A' + i)) : "D" + std::to_string(i));
    mission.fleet = dex::SharedTable<std::vector<std::string>>(std::move(names));
    fleet::DroneSettings s;
    s.name = "A";
    s.adapter = "sim";
    a = adapters.create("sim", s, fleet::generic_multirotor("Quad"), loop).drone;
    guard = std::make_unique<dex::SeparationGuard>(mission, loop, dex::SeparationHooks{&trace, {}});
    guard->fly(0, *a, fleet::Limits{});
  }
  /// Mission time moves on to `t` (the guard looks at a drone's pairs at most every 0.2 s).
  void at(double t) {
    loop.at(t, [] {});
    loop.run_until(t);
  }
  void sample(int d, double t, double x, double y = 0.0) {
    mid::DroneState s;
    s.t = t;
    s.x = x;
    s.y = y;
    s.z = 5.0;
    s.landed = false;
    guard->update(d, s);
  }
  int conflicts() const {
    int n = 0;
    for (const dex::TraceEvent& e : trace.events) n += e.event == "conflict";
    return n;
  }
};

// A MAVLink vehicle sends its position in two messages (LOCAL_POSITION_NED, GLOBAL_POSITION_INT)
// a millisecond apart, each a little off the other: 5 cm in 1 ms read as 50 m/s would see B,
// 60 m ahead, met within a second. A velocity spans at least kMinVelocityDtS (20 ms).
TEST(SeparationGuard, TwoPositionsAMillisecondApartDoNotMakeASpeed) {
  Guarded g(2);
  g.sample(1, 0.0, 60.0);
  g.sample(0, 0.0, 0.0);
  g.at(0.1);
  g.sample(0, 0.1, 0.0);
  g.at(0.2);
  g.sample(0, 0.101, 0.05);  // checked now: 0.2 s since the first look
  EXPECT_EQ(g.conflicts(), 0);
  EXPECT_EQ(g.guard->pairs_predicted(), 0u) << "A counts as standing still";
  // 21 ms after the sample it is measured from, 10 cm is a speed (4.8 m/s), and B, 60 m
  // away, is no conflict.
  g.at(0.4);
  g.sample(0, 0.121, 0.1);
  EXPECT_EQ(g.guard->pairs_predicted(), 1u);
  EXPECT_EQ(g.conflicts(), 0);
}

// The neighbours a drone's pairs are looked for in: the cells its reach spans. Walked as a
// square of cells, or, when that square holds more cells than are occupied, through the
// occupied cells: both find B, two cells (62 m each) east of A within a reach of two cells,
// and neither finds C, six cells east.
TEST(SeparationGuard, BothNeighbourWalksFindTheDronesInReachAndOnlyThem) {
  for (int far_away : {0, 40}) {  // 3 occupied cells (fewer than the 25 in reach), or 43
    Guarded g(3 + far_away);
    g.sample(1, 0.0, 130.0);
    g.sample(2, 0.0, 400.0);
    for (int i = 0; i < far_away; ++i) g.sample(3 + i, 0.0, -1000.0 - 100.0 * i, 5000.0);
    g.sample(0, 0.0, 0.0);
    g.at(0.3);
    g.sample(0, 0.3, 6.0);  // 20 m/s east: reach 2 + 3 × (20 + 20) = 122 m, two cells
    EXPECT_EQ(g.guard->pairs_predicted(), 1u) << far_away << " far away drones";
  }
}

// A velocity of hundreds of millions of m/s (a position that jumped 10,000 km, as a corrupted
// or forged sample may) spans tens of millions of cells each way: walked as a square, 10^15
// cells and the DEX stuck at 100 % CPU with its drone in the air. The walk goes through the
// occupied cells instead, and still finds every drone within that reach.
TEST(SeparationGuard, AnAbsurdSpeedLooksThroughTheOccupiedCellsOnly) {
  Guarded g(3);
  g.sample(1, 0.0, 130.0);
  g.sample(2, 0.0, 400.0);
  g.sample(0, 0.0, 0.0);
  g.at(0.3);
  g.sample(0, 0.05, 1.0e7);
  EXPECT_EQ(g.guard->pairs_predicted(), 2u);
}


// Drones on rows of a show, each flying along its own: a neighbour whose course stays on its
// row, 20 m north of A's, is let go before its course is worked out (its speed alone, 10 m/s
// over the 3 s horizon, could reach A's row). One crossing A's row well ahead of A, 20 m/s
// east and 10 m/s south, could come near, and is foreseen (and is no conflict).
TEST(SeparationGuard, ADroneOnARowFartherThanEitherCanFlyIsNotForeseen) {
  for (bool crossing : {false, true}) {
    Guarded g(2);
    for (int i = 0; i <= 4; ++i) {
      const double t = 0.1 * i;
      g.at(t);
      if (crossing) g.sample(1, t, 20.0 * t, 20.0 - 10.0 * t);
      else g.sample(1, t, 10.0 * t, 20.0);
      g.sample(0, t, 10.0 * t);
    }
    EXPECT_GE(g.guard->pairs_predicted(), 1u) << crossing;
    const std::uint64_t foreseen = crossing ? g.guard->pairs_predicted() : 0u;
    EXPECT_EQ(g.guard->pairs_foreseen(), foreseen) << crossing;
    EXPECT_EQ(g.conflicts(), 0);
  }
}

// Drones of a show flown here, each along its own row to a goal on it: a neighbour's course
// stays on its row, so B's row 5 m north of A's is let go before B's course is worked out,
// although B's speed limit alone (10 m/s over the 3 s horizon) would reach A's row. B flying
// across towards A's row is foreseen.
TEST(SeparationGuard, ANeighbourFlyingAlongItsOwnRowIsNotForeseen) {
  for (double b_goal_north : {5.0, 0.0}) {
    Guarded g(2);
    fleet::DroneSettings s;
    s.name = "B";
    s.adapter = "sim";
    s.home = {0.0, 5.0, 0.0};
    std::unique_ptr<mid::Drone> b = g.adapters.create("sim", s, fleet::generic_multirotor("Quad"), g.loop).drone;
    g.guard->fly(1, *b, fleet::Limits{});
    std::vector<mid::Drone*> both{g.a.get(), b.get()};
    for (int d = 0; d < 2; ++d) both[d]->subscribe([&g, d](const mid::DroneState& st) { g.guard->update(d, st); });
    auto fly_both = [&](const mid::ActionRequest& ra, const mid::ActionRequest& rb) {
      int done = 0;
      g.a->start(ra, [&](const mid::ActionEnd&) { ++done; });
      b->start(rb, [&](const mid::ActionEnd&) { ++done; });
      while (done < 2 && g.loop.now() < 60.0) g.at(g.loop.now() + 0.05);
    };
    fly_both({"Arm", {}}, {"Arm", {}});
    fly_both({"Takeoff", {5}}, {"Takeoff", {5}});
    const std::uint64_t before = g.guard->pairs_foreseen();
    g.a->start({"FlyTo", {100, 0, 5}}, [](const mid::ActionEnd&) {});
    b->start({"FlyTo", {100, b_goal_north, 5}}, [](const mid::ActionEnd&) {});
    g.at(g.loop.now() + 1.0);
    EXPECT_GE(g.guard->pairs_predicted(), 5u) << b_goal_north;
    if (b_goal_north == 5.0)
      EXPECT_EQ(g.guard->pairs_foreseen(), before) << "B flies along its own row";
    else
      EXPECT_GT(g.guard->pairs_foreseen(), before) << "B flies towards A's row";
  }
}

// Two courses whose boxes over the horizon lie the minimum apart never come within it: the
// box test that lets far pairs go (before their courses are stepped through) is never wrong.
// Random courses towards goals and straight ones, placed so that many are near, each pair
// followed every 5 ms of the horizon.
TEST(SeparationPrediction, CoursesWhoseBoxesLieApartNeverComeWithinTheMinimum) {
  fleet::Separation min;
  fleet::Limits limits;
  std::uint64_t seed = 42;
  auto uniform = [&seed](double lo, double hi) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * static_cast<double>(seed >> 11) / 9007199254740992.0;
  };
  auto course = [&](bool to_goal) {
    const dex::Vec p{uniform(-20, 20), uniform(-20, 20), uniform(4, 8)};
    const dex::Vec v{uniform(-8, 8), uniform(-8, 8), uniform(-1, 1)};
    if (!to_goal) return dex::Course{.p = p, .v = v};
    return dex::goal_course(p, v, {uniform(-40, 40), uniform(-40, 40), uniform(4, 8)}, limits);
  };
  int apart = 0, near = 0;
  for (int i = 0; i < 2000; ++i) {
    const dex::Course a = course(i % 3 != 0), b = course(i % 2 == 0);
    if (!dex::sweep(a, 3.0).apart(dex::sweep(b, 3.0), min.horizontal_m)) continue;
    ++apart;
    double closest = 1e9;
    for (int ms = 0; ms <= 3000; ms += 5) {
      const dex::Vec pa = a.at(ms / 1000.0), pb = b.at(ms / 1000.0);
      closest = std::min(closest, std::hypot(pa.x - pb.x, pa.y - pb.y));
    }
    EXPECT_GE(closest, min.horizontal_m) << i;
    near += closest < 10.0;
  }
  EXPECT_GT(apart, 1000);
  EXPECT_GT(near, 100) << "pairs apart by little, where a wrong box would show";
}

TEST(SeparationPrediction, ADroneStandingWithAGoalAheadIsPredictedToMove) {
  fleet::Separation min;  // 2 m, 1 m
  fleet::Limits limits;   // 10 m/s, 4 m/s²
  // Both hover 8 m short of the point where their courses cross, about to set off: from
  // their samples (standing) nothing comes; along their goals both reach it in 2 s.
  dex::Course a = dex::goal_course({-8, 0, 5}, {}, {8, 0, 5}, limits);
  dex::Course b = dex::goal_course({0, -8, 5}, {}, {0, 8, 5}, limits);
  EXPECT_FALSE(dex::predict({-8, 0, 5}, {}, {0, -8, 5}, {}, min, 3.0).conflict);
  dex::Prediction p = dex::predict_courses(a, b, min, 3.0);
  EXPECT_TRUE(p.conflict);
  EXPECT_GT(p.in_s, 1.0);
  EXPECT_LT(p.in_s, 2.0);
  // Speeding up from a stop at 4 m/s² to 10 m/s, and stopping at the goal 16 m ahead.
  EXPECT_NEAR(a.at(1.0).x, -6.0, 1e-9);
  EXPECT_NEAR(a.at(2.0).x, 0.0, 1e-9);
  EXPECT_NEAR(a.at(10.0).x, 8.0, 1e-9);
  // A goal that ends short of the other drone is still no conflict.
  dex::Course short_of = dex::goal_course({0, 0, 5}, {}, {10, 0, 5}, limits);
  EXPECT_FALSE(dex::predict_courses(short_of, dex::Course{.p = {20, 0, 5}}, min, 3.0).conflict);
}

// A flown here on the simulator (armed, 5 m up, flying east to x = 200), B fed by hand: B
// stands in A's way, A gives way to it, then B comes alongside A, within the minimum.
struct HeldBeside : Guarded {
  mid::SubscriptionId sub = 0;
  double t = 0.0;
  HeldBeside() : Guarded(2) {
    sub = a->subscribe([this](const mid::DroneState& s) { guard->update(0, s); });
    fly({"Arm", {}});
    fly({"Takeoff", {5}});
    a->start({"FlyTo", {200, 0, 5}}, [](const mid::ActionEnd&) {});
    for (t = loop.now(); !a->motion_held() && t < 60.0; t += 0.05) {
      sample(1, t, 40.0);
      at(t);
    }
    // Braked to a stop short of B.
    for (double t0 = t; t < t0 + 4.0; t += 0.05) {
      sample(1, t, 40.0);
      at(t);
    }
  }
  ~HeldBeside() { a->unsubscribe(sub); }
  void fly(const mid::ActionRequest& r) {
    bool done = false;
    a->start(r, [&](const mid::ActionEnd&) { done = true; });
    while (!done) at(loop.now() + 0.05);
  }
  /// B at (x, y) from A now, for `s` seconds, `vy` m/s north; the first resume, if any.
  const dex::TraceEvent* beside(double x, double y, double vy, double s) {
    const mid::DroneState here = a->state();
    for (double t0 = t; t < t0 + s; t += 0.05) {
      sample(1, t, here.x + x, here.y + y + vy * (t - t0));
      at(t);
      for (const dex::TraceEvent& e : trace.events)
        if (e.event == "resume") return &e;
    }
    return nullptr;
  }
};

// B flies off north from beside A, 0.5 m away: the two part, and a course that parts was once
// enough to fly on, within the minimum. A flies on only once B is 2 m away.
TEST(SeparationGuard, AHeldDroneDoesNotFlyOnInsideTheMinimumOfTheDroneItGaveWayTo) {
  HeldBeside g;
  ASSERT_TRUE(g.a->motion_held());
  const dex::TraceEvent* resume = g.beside(0.0, 0.5, 1.0, 5.0);
  ASSERT_NE(resume, nullptr);
  ASSERT_TRUE(resume->distance.has_value());
  EXPECT_GE(*resume->distance, 2.0);
}

// B stands 1 m behind A: A's course leads away from it, and it flies on at once.
TEST(SeparationGuard, AHeldDroneFliesOnAwayFromADroneStandingWithinTheMinimum) {
  HeldBeside g;
  ASSERT_TRUE(g.a->motion_held());
  const dex::TraceEvent* resume = g.beside(-1.0, 0.0, 0.0, 2.0);
  ASSERT_NE(resume, nullptr);
  ASSERT_TRUE(resume->distance.has_value());
  EXPECT_LT(*resume->distance, 2.0);
}

// The same drone standing 1 m ahead of A, in its way: A stays held.
TEST(SeparationGuard, AHeldDroneStaysHeldWithADroneStandingWithinTheMinimumAhead) {
  HeldBeside g;
  ASSERT_TRUE(g.a->motion_held());
  EXPECT_EQ(g.beside(1.0, 0.0, 0.0, 2.0), nullptr);
  EXPECT_TRUE(g.a->motion_held());
}
}  // namespace
}  // namespace eamos::test
