#!/usr/bin/env bash
# Runs every test of a built tree. First the cases labelled `alone` with nothing beside them:
# the browser's, which hold a latency bound, and Listing 2 on SITL, which holds each position
# report of an orbit to 5 %. Then the real-time suites (labels `realtime` and
# `realtime_serial`: SITL firmware, DDS processes, sim-vehicles, signals) at normal priority:
# PX4's SITL cases, also with nothing beside them (SIH runs on the wall clock); then
# ArduCopter's SITL cases one at a time with the other real-time cases that need not run alone
# beside them, two at a time; then the ones that run alone (RUN_SERIAL). Beside the last two,
# at the lowest priority (nice 19), the fuzzers' build and smoke run, then every other test.
# The real-time suites leave part of the two cores idle (a SITL case uses about one); the
# low-priority work fills it without taking CPU the real-time ones ask for.
# Usage: scripts/test.sh BUILD_DIR FUZZ_BUILD_DIR FUZZ_SECONDS_PER_TARGET
set -uo pipefail
BUILD=${1:-build}
FUZZ_BUILD=${2:-$BUILD-fuzz}
FUZZ_SECONDS=${3:-5}
cd "$(dirname "$0")/.."
JOBS=$(nproc)
CTEST=(ctest --test-dir "$BUILD" --output-on-failure -j "$JOBS")
# Only a test that flies on the wall clock (labels `alone` and `realtime`) runs once more
# when it fails: one that fails twice fails the run, and the first failure stays in the log.
# Every other test fails the run the first time it fails, so a flaky one shows.
RETRY=(--repeat until-pass:2)
BESIDE_LOG="$BUILD/Testing/beside-realtime.log"
BESIDE_SITL_LOG="$BUILD/Testing/beside-sitl.log"
# Test names: the autopilot firmware's cases (tests/mavlink_adapter/sitl*_test.cpp) and of
# them those that fly PX4 (every other one flies ArduCopter).
SITL='Sitl'
SITL_PX4='Sitl[^ ]*[/_]PX4( |$)'
mkdir -p "$BUILD/Testing"

"${CTEST[@]}" "${RETRY[@]}" -L alone
alone_rc=$?
# PX4's SIH runs on the wall clock, and any neighbour slows that clock until a case fails: a
# light sim-vehicle case at normal priority (to 0.77 of mission time), and the other tests'
# processes at nice 19 (to 0.48). PX4's SITL cases therefore run next, also with nothing
# beside them, before the low-priority work starts.
"${CTEST[@]}" "${RETRY[@]}" -L realtime -LE alone -R "$SITL_PX4"
px4_rc=$?

# The cases on autopilot firmware run one at a time (RUN_SERIAL, fixed ports) and use about
# one core. ArduCopter's simulation steps with its firmware, so beside its cases the real-time
# cases that need not run alone (the RESOURCE_LOCK suites: DDS processes, network namespaces;
# the sim-vehicle cases) run, two at a time. Then the real-time suites that run alone (label
# `realtime_serial`).
realtime_phase() {
  set +m  # its ctest runs stay in the phase's process group
  local rc=0
  "${CTEST[@]}" "${RETRY[@]}" -L realtime -LE 'alone|realtime_serial' -E "$SITL" >"$BESIDE_SITL_LOG" 2>&1 &
  local beside_sitl=$!
  "${CTEST[@]}" "${RETRY[@]}" -L realtime -LE alone -R "$SITL" -E "$SITL_PX4" || rc=1
  wait "$beside_sitl" || rc=1
  echo
  echo "test: the real-time cases that ran beside ArduCopter's SITL cases:"
  cat "$BESIDE_SITL_LOG"
  "${CTEST[@]}" "${RETRY[@]}" -L realtime_serial -LE alone -E "$SITL" || rc=1
  return $rc
}

# Each in its own process group, so that an interrupted run stops them too (fuzzers, test
# processes, compilers).
set -m
nice -n 19 bash -c '
  rc=0
  bash scripts/fuzz.sh "$1" "$2" || rc=1
  shift 2
  "$@" -LE "realtime|alone" || rc=1
  exit $rc' beside "$FUZZ_BUILD" "$FUZZ_SECONDS" "${CTEST[@]}" >"$BESIDE_LOG" 2>&1 &
beside=$!
echo "test: the fuzzers and the tests not labelled realtime run beside these, at low priority ($BESIDE_LOG)"
realtime_phase &
realtime=$!
set +m
prebuild=
trap 'for g in "$beside" "$realtime" $prebuild; do kill -TERM -- -"$g" 2>/dev/null; done; exit 130' INT TERM

wait "$beside"
beside_rc=$?
# With EAMOS_PREBUILD_SANITIZERS=1 (.ci/run), the core the real-time cases leave idle once the
# low-priority work is done builds make sanitize's trees, at the lowest priority, until the
# real-time cases end; make sanitize goes on from where it stopped (scripts/sanitize.sh prebuild).
if [ -n "${EAMOS_PREBUILD_SANITIZERS:-}" ] && kill -0 "$realtime" 2>/dev/null; then
  set -m
  nice -n 19 bash scripts/sanitize.sh prebuild "$BUILD" >"$BUILD/Testing/sanitizer-prebuild.log" 2>&1 &
  prebuild=$!
  set +m
fi
wait "$realtime"
realtime_rc=$?
if [ -n "$prebuild" ]; then
  kill -TERM -- -"$prebuild" 2>/dev/null
  wait "$prebuild"
  echo "test: the sanitizer trees built beside the real-time cases until they ended: $(tail -1 "$BUILD/Testing/sanitizer-prebuild.log")"
fi
trap - INT TERM

echo
echo "test: the fuzzers and the tests not labelled realtime, as they ran beside the real-time ones:"
cat "$BESIDE_LOG"
echo
verdict() { [ "$1" -eq 0 ] && echo "test: $2 passed" || echo "test: $2 FAILED (above)"; }
verdict "$alone_rc" "tests run alone"
verdict "$px4_rc" "PX4's SITL tests"
verdict "$realtime_rc" "other real-time tests"
verdict "$beside_rc" "fuzzers and other tests"
[ "$alone_rc" -eq 0 ] && [ "$px4_rc" -eq 0 ] && [ "$realtime_rc" -eq 0 ] && [ "$beside_rc" -eq 0 ]
