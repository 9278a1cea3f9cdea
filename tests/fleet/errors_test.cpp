// Broken fleet files: each problem is an error at the offending node, "what; how to fix",
// all of them in one pass, and nothing ever escapes parse_fleet.
#include <gtest/gtest.h>

#include <random>

#include "helpers.h"

namespace eamos::fleet {
namespace {

using test::first_error;
using test::parse;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(Errors, UnknownKeyReportsLineColumnAndSuggestion) {
  auto p = parse("types:\n  Scout:\n    limts: {max_speed: 3}\n");
  EXPECT_FALSE(p.ok);
  ASSERT_EQ(p.diags.error_count(), 1u);
  Diagnostic d = first_error(p.diags);
  EXPECT_EQ(d.loc.line, 3);
  EXPECT_EQ(d.loc.col, 5);
  EXPECT_TRUE(contains(d.message, "unknown key 'limts'")) << d.message;
  EXPECT_TRUE(contains(d.message, "did you mean 'limits'?")) << d.message;
}

TEST(Errors, EveryBadGoalToleranceIsReportedAtItsValueInOnePass) {
  auto p = parse("types:\n  Scout:\n    tolerance: {horizontal: 0, vertical: -1, sped: 0.2}\n"
                 "  Lifter:\n    tolerance: 0.5\n");
  EXPECT_FALSE(p.ok);
  ASSERT_EQ(p.diags.error_count(), 4u) << p.diags.format();
  const auto& d = p.diags.items();
  EXPECT_TRUE(contains(d[0].message, "horizontal of tolerance of type 'Scout' must be positive; got '0'")) << d[0].message;
  EXPECT_EQ(d[0].loc.line, 3);
  EXPECT_EQ(d[0].loc.col, 29);
  EXPECT_TRUE(contains(d[1].message, "vertical of tolerance of type 'Scout' must be positive")) << d[1].message;
  EXPECT_TRUE(contains(d[2].message, "did you mean 'speed'?")) << d[2].message;
  EXPECT_TRUE(contains(d[3].message, "tolerance of type 'Lifter' must be a map {horizontal: M, vertical: M, speed: M/S}"))
      << d[3].message;
  EXPECT_EQ(d[3].loc.line, 5);
}

// The CLI prints after the fleet's SourceFile is gone (compile_file returns, the Fleet and
// its source die); a diagnostic pointing into the source printed freed memory or crashed.
TEST(Errors, DiagnosticsStayPrintableAfterTheirSourceIsFreed) {
  Diagnostics diags;
  {
    Fleet fleet;
    parse_fleet(std::make_shared<SourceFile>("gone.yaml", "drones:\n  D1: {home: [0, 0]}\n"),
                fleet, diags);
  }
  // Overwrite freed memory so a dangling pointer would show as garbage, not the old text.
  std::vector<std::string> filler(64, std::string(256, 'X'));
  std::string text = diags.format();
  EXPECT_TRUE(contains(text, "gone.yaml:2:")) << text;
  EXPECT_TRUE(contains(text, " D1: {home: [0, 0]}\n")) << text;
  EXPECT_FALSE(contains(text, "XXXX")) << text;
}

TEST(Errors, UnknownKeyFarFromAnyListsTheAllowedKeys) {
  auto p = parse("planes: {}\n");
  EXPECT_FALSE(p.ok);
  EXPECT_TRUE(contains(first_error(p.diags).message, "expected types, drones or safety"))
      << first_error(p.diags).message;
}

TEST(Errors, FormattedErrorShowsFileLineColumnAndTheValueUnderlined) {
  auto p = parse("drones:\n  Drone1:\n    failsafe: lnd\n");
  EXPECT_EQ(p.diags.format(),
            "fleet.yaml:3:15: error: unknown failsafe 'lnd'; did you mean 'land'?\n"
            "     failsafe: lnd\n"
            "               ^~~\n");
}

TEST(Errors, UnknownCapabilityIsAnErrorWithSuggestion) {
  auto p = parse("types:\n  Scout:\n    capabilities: [Arm, TakeOff, Teleport]\n");
  EXPECT_FALSE(p.ok);
  ASSERT_EQ(p.diags.error_count(), 2u);
  EXPECT_EQ(p.diags.items()[0].loc.col, 25);
  EXPECT_TRUE(contains(p.diags.items()[0].message, "did you mean 'Takeoff'?"));
  EXPECT_TRUE(contains(p.diags.items()[1].message, "unknown capability 'Teleport'"));
}

TEST(Errors, PropertyOrSensorListedAsCapabilityIsAnError) {
  auto p = parse("types:\n  Scout:\n    capabilities: [Battery, Sensor1]\n");
  ASSERT_EQ(p.diags.error_count(), 2u);
  EXPECT_TRUE(contains(p.diags.items()[0].message, "is a property")) << p.diags.format();
  EXPECT_TRUE(contains(p.diags.items()[1].message, "`sensors: N`")) << p.diags.format();
}

TEST(Errors, CapabilityListedTwiceIsOnlyAWarning) {
  auto p = parse("types:\n  Scout:\n    capabilities: [Arm, Arm]\n");
  EXPECT_TRUE(p.ok);
  EXPECT_EQ(p.diags.warning_count(), 1u);
}

TEST(Errors, CapabilitiesMustBeAList) {
  auto p = parse("types:\n  Scout:\n    capabilities: Arm\n");
  EXPECT_FALSE(p.ok);
  EXPECT_TRUE(contains(first_error(p.diags).message, "must be a list")) << p.diags.format();
}

TEST(Errors, WrongValueTypeIsAnError) {
  auto p = parse("drones:\n  Drone1:\n    battery: full\n    home: {x: 1}\n    connection: [a]\n");
  EXPECT_FALSE(p.ok);
  ASSERT_EQ(p.diags.error_count(), 3u) << p.diags.format();
  EXPECT_EQ(p.diags.items()[0].message, "battery of drone 'Drone1' must be a number; got 'full'");
  EXPECT_TRUE(contains(p.diags.items()[1].message, "three numbers [x, y, z]; got a map"));
  EXPECT_TRUE(contains(p.diags.items()[2].message, "must be text; got a list"));
}

TEST(Errors, QuotedNumberIsTextNotANumber) {
  auto p = parse("types:\n  Scout:\n    sensors: \"2\"\n");
  EXPECT_FALSE(p.ok);
  EXPECT_TRUE(contains(first_error(p.diags).message, "must be a whole number")) << p.diags.format();
}

TEST(Errors, InfiniteOrNanNumberIsAnError) {
  auto p = parse("drones:\n  Drone1:\n    home: [.inf, .nan, 0]\n");
  EXPECT_EQ(p.diags.error_count(), 2u) << p.diags.format();
}

TEST(Errors, NegativeLimitIsAnError) {
  auto p = parse("types:\n  Scout:\n    limits: {max_speed: -1, max_climb: 0}\n");
  EXPECT_FALSE(p.ok);
  ASSERT_EQ(p.diags.error_count(), 2u);
  Diagnostic d = first_error(p.diags);
  EXPECT_EQ(d.loc.col, 25);
  EXPECT_TRUE(contains(d.message, "max_speed of type 'Scout' must be positive; got '-1'")) << d.message;
}

TEST(Errors, UnknownLimitSuggestsTheNearestOne) {
  auto p = parse("drones:\n  Drone1:\n    limits: {max_sped: 3}\n");
  EXPECT_TRUE(contains(first_error(p.diags).message, "did you mean 'max_speed'?"));
}

TEST(Errors, UnknownFailsafeIsAnError) {
  auto p = parse("drones:\n  Drone1:\n    failsafe: parachute\n");
  EXPECT_FALSE(p.ok);
  EXPECT_EQ(first_error(p.diags).message,
            "unknown failsafe 'parachute'; use land, return_home or hover");
}

TEST(Errors, OnlySimAndMavlinkAdaptersExist) {
  auto p = parse("types:\n  Scout:\n    adapter: px4\ndrones:\n  Drone1:\n    adapter: mavlnk\n");
  EXPECT_FALSE(p.ok);
  ASSERT_EQ(p.diags.error_count(), 2u);
  EXPECT_EQ(p.diags.items()[0].message, "unknown adapter 'px4'; use sim or mavlink");
  EXPECT_EQ(p.diags.items()[1].message, "unknown adapter 'mavlnk'; did you mean 'mavlink'?");
}

TEST(Errors, SensorBeyondEveryTypesCountIsAnError) {
  auto p = parse("drones:\n  Drone1:\n    sensors: {Sensor9: 1}\n");
  EXPECT_FALSE(p.ok);
  Diagnostic d = first_error(p.diags);
  EXPECT_EQ(d.loc.line, 3);
  EXPECT_EQ(d.loc.col, 15);
  EXPECT_TRUE(contains(d.message, "beyond every type's sensor count (at most 8)")) << d.message;
}

TEST(Errors, SensorThatIsNotSensorKIsAnError) {
  auto p = parse("drones:\n  Drone1:\n    sensors: {Temperature: 1, Sensor0: 2}\n");
  EXPECT_EQ(p.diags.error_count(), 2u);
  EXPECT_TRUE(contains(first_error(p.diags).message, "unknown sensor 'Temperature'"));
}

TEST(Errors, SensorWithUnknownFieldIsAnError) {
  auto p = parse("drones:\n  Drone1:\n    sensors: {Sensor1: {value: 1, gradiant: [0, 0, 0]}}\n");
  EXPECT_TRUE(contains(first_error(p.diags).message, "did you mean 'gradient'?")) << p.diags.format();
}

TEST(Errors, SensorCountOutsideZeroToMaxIsAnError) {
  auto p = parse("types:\n  A:\n    sensors: -1\n  B:\n    sensors: 100000000000\n");
  EXPECT_EQ(p.diags.error_count(), 2u) << p.diags.format();
  EXPECT_EQ(p.fleet.types.at("A").sensors, 8);  // the error leaves the default
}

TEST(Errors, BatteryAndSysidOutOfRangeAreErrors) {
  auto p = parse("drones:\n  Drone1:\n    battery: 150\n    sysid: 0\n");
  ASSERT_EQ(p.diags.error_count(), 2u);
  EXPECT_TRUE(contains(p.diags.items()[0].message, "from 0 to 100"));
  EXPECT_TRUE(contains(p.diags.items()[1].message, "from 1 to 255"));
}

TEST(Errors, PriorityThatIsNotAWholeNumberFromOneUpIsAnErrorAtItsLine) {
  auto p = parse("drones:\n  Drone1:\n    priority: 0\n  Drone2:\n    priority: 1.5\n  Drone3:\n    priority: 2\n");
  ASSERT_EQ(p.diags.error_count(), 2u) << p.diags.format();
  EXPECT_EQ(p.diags.items()[0].loc.line, 3);
  EXPECT_TRUE(contains(p.diags.items()[0].message, "from 1 (goes first)")) << p.diags.items()[0].message;
  EXPECT_EQ(p.diags.items()[1].loc.line, 5);
  EXPECT_EQ(p.fleet.drones.at("Drone3").priority, 2);
  EXPECT_EQ(p.fleet.drones.at("Drone1").priority, 0);  // the error leaves it unset
}

TEST(Errors, TimeoutForUnknownActionSuggestsTheNearest) {
  auto p = parse("drones:\n  Drone1:\n    timeouts: {Takeof: 40, Land: -1}\n");
  ASSERT_EQ(p.diags.error_count(), 2u);
  EXPECT_TRUE(contains(p.diags.items()[0].message, "did you mean 'Takeoff'?"));
  EXPECT_TRUE(contains(p.diags.items()[1].message, "positive number of seconds"));
}

TEST(Errors, DuplicateKeyIsAnError) {
  auto p = parse("drones:\n  Drone1:\n    battery: 50\n    battery: 60\n");
  EXPECT_FALSE(p.ok);
  Diagnostic d = first_error(p.diags);
  EXPECT_EQ(d.loc.line, 4);
  EXPECT_TRUE(contains(d.message, "appears twice")) << d.message;
}

TEST(Errors, NameAMissionCannotWriteIsAnError) {
  auto p = parse("types:\n  my scout: {}\ndrones:\n  1st: {}\n");
  EXPECT_EQ(p.diags.error_count(), 2u);
  EXPECT_TRUE(contains(first_error(p.diags).message, "cannot be written in a mission"));
}

TEST(Errors, FileThatIsNotAMapIsAnError) {
  auto p = parse("- Drone1\n- Drone2\n");
  EXPECT_FALSE(p.ok);
  EXPECT_TRUE(contains(first_error(p.diags).message, "the fleet file must be a map"));
}

TEST(Errors, YamlSyntaxErrorIsReportedAtItsMark) {
  auto p = parse("types:\n  Scout: {sensors: 2\n");
  EXPECT_FALSE(p.ok);
  ASSERT_EQ(p.diags.error_count(), 1u);
  Diagnostic d = first_error(p.diags);
  EXPECT_TRUE(d.loc.known());
  EXPECT_GE(d.loc.line, 2);
  EXPECT_TRUE(contains(d.message, "YAML syntax error")) << d.message;
}

TEST(Errors, TabIndentationIsASyntaxErrorThatSaysSo) {
  auto p = parse("types:\n\tScout:\n");
  EXPECT_FALSE(p.ok);
  EXPECT_EQ(first_error(p.diags).loc.line, 2);
  EXPECT_TRUE(contains(first_error(p.diags).message, "indent with spaces")) << p.diags.format();
}

TEST(Errors, StrayCommaIsASyntaxErrorNotAHang) {
  // yaml-cpp 0.7's own LoadAll loops forever allocating on this input.
  auto p = parse(",ypes:\n  Scout: {}\n");
  EXPECT_FALSE(p.ok);
  ASSERT_EQ(p.diags.error_count(), 1u);
  EXPECT_EQ(first_error(p.diags).message,
            "YAML syntax error: unexpected ','; remove it or quote the text it belongs to");
  EXPECT_EQ(first_error(p.diags).loc.col, 1);
}

TEST(Errors, TextAfterAnEarlyEndOfTheDocumentIsASyntaxError) {
  // yaml-cpp ends the document at the unindented "/b" and would start another there.
  auto p = parse("- macro: x\n  condition:\n    (a in (\n\"/b\",\n    \"-c\"\n    )  )\n");
  EXPECT_FALSE(p.ok);
  Diagnostic d = first_error(p.diags);
  EXPECT_EQ(d.loc.line, 4);
  EXPECT_EQ(d.loc.col, 1);
  EXPECT_TRUE(contains(d.message, "the file should have ended before this text")) << d.message;
}

TEST(Errors, SecondYamlDocumentIsAnError) {
  auto p = parse("types: {}\n---\ndrones: {}\n");
  EXPECT_FALSE(p.ok);
  EXPECT_TRUE(contains(first_error(p.diags).message, "one YAML document"));
}

TEST(Errors, AllErrorsAreReportedInOnePass) {
  auto p = parse(
      "types:\n"
      "  Scout:\n"
      "    adapter: ros\n"
      "    capabilities: [Fly]\n"
      "drones:\n"
      "  Drone1:\n"
      "    failsafe: explode\n"
      "    home: [0, 0]\n");
  EXPECT_FALSE(p.ok);
  ASSERT_EQ(p.diags.error_count(), 4u) << p.diags.format();
  std::vector<int> lines;
  for (const auto& d : p.diags.items()) lines.push_back(d.loc.line);
  EXPECT_EQ(lines, (std::vector<int>{3, 4, 7, 8}));
}

TEST(Errors, GarbageInputIsAnErrorNotACrash) {
  std::mt19937 random(12345);
  for (int round = 0; round < 300; ++round) {
    std::string text(1 + random() % 300, '\0');
    for (char& c : text) c = static_cast<char>(random() % 256);
    auto p = parse(text);
    // Some garbage is valid YAML with nothing in it (a leading '%' directive or '#').
    if (p.ok) {
      EXPECT_TRUE(p.fleet.types.empty() && p.fleet.drones.empty()) << "round " << round;
    } else {
      EXPECT_TRUE(p.diags.has_errors()) << "round " << round;
    }
    for (const auto& d : p.diags.items())
      EXPECT_LE(d.loc.line, static_cast<int>(p.fleet.source->line_starts.size())) << "round " << round;
    EXPECT_NO_THROW(p.diags.format());
  }
}

TEST(Errors, GarbledFleetFileIsReportedNotACrash) {
  const std::string example = R"(types:
  Scout:
    adapter: sim
    capabilities: [Arm, Takeoff, FlyTo]
    sensors: 2
    limits: {max_speed: 8, max_climb: 2.5}
drones:
  Drone1:
    home: [0, 0, 0]
    sensors: {Sensor1: 120, Sensor2: {value: 10, gradient: [0.5, 0, 0]}}
    limits: {max_speed: 5}
    failsafe: land
    timeouts: {Takeoff: 40}
)";
  ASSERT_TRUE(parse(example).ok);
  std::mt19937 random(777);
  const std::string alphabet = " :-[]{},#&*!|>'\"%@`\n\t0123456789abcXYZ";
  for (int round = 0; round < 500; ++round) {
    std::string text = example;
    for (int edits = 1 + random() % 4; edits > 0; --edits)
      text[random() % text.size()] = alphabet[random() % alphabet.size()];
    auto p = parse(text);
    // ok and "no errors" must agree: a caller trusts the return value alone.
    EXPECT_EQ(p.ok, !p.diags.has_errors()) << text;
    for (const auto& d : p.diags.items()) {
      EXPECT_LE(d.loc.line, static_cast<int>(p.fleet.source->line_starts.size())) << text;
      EXPECT_FALSE(d.message.empty()) << text;
    }
  }
}

TEST(Errors, GarbageInsideAValidShapeIsAnErrorNotACrash) {
  auto p = parse(std::string("drones:\n  Drone1:\n    connection: \"\x01://\x02:\x03\"\n    battery: \"\xff\xfe\"\n"));
  EXPECT_FALSE(p.ok);
  EXPECT_EQ(p.diags.error_count(), 2u) << p.diags.format();  // no link URL, no number
  for (char control : {'\x01', '\x02', '\x03'}) EXPECT_EQ(p.diags.format().find(control), std::string::npos);
}

TEST(Errors, DeeplyNestedInputIsAnErrorNotACrash) {
  auto p = parse(std::string(100000, '['));
  EXPECT_FALSE(p.ok);
  EXPECT_TRUE(p.diags.has_errors());
}

}  // namespace
}  // namespace eamos::fleet
