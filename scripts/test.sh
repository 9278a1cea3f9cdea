#!/usr/bin/env bash
# Runs every test of a built tree. First the cases labelled `alone` with nothing beside them:
# the browser's, which hold a latency bound, and Listing 2 on SITL, which holds each position
# report of an orbit to 5 %. Then the real-time suites (label `realtime`: SITL firmware, DDS
# processes, signals) at normal priority: the SITL cases one at a time with the cases that fly
# a sim-vehicle one at a time beside them, then the others. Beside all of those, at the lowest
# priority (nice 19), the fuzzers' build and smoke run, then every other test. The real-time
# suites leave part of the two cores idle (a SITL case uses about one); the low-priority work
# fills it without taking CPU the real-time ones ask for.
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
FLYING_LOG="$BUILD/Testing/flying-beside-sitl.log"
# Test names: the autopilot firmware's cases (tests/mavlink_adapter/sitl*_test.cpp) and the
# cases that fly a sim-vehicle (the same set scripts/sanitize.sh calls FLYING).
SITL='Sitl'
FLYING='^(Mavlink|HostileVehicle|SimVehicle)'
mkdir -p "$BUILD/Testing"

"${CTEST[@]}" "${RETRY[@]}" -L alone
alone_rc=$?

# Its own process group, so that an interrupted run stops it too (fuzzers, test processes).
set -m
nice -n 19 bash -c '
  rc=0
  bash scripts/fuzz.sh "$1" "$2" || rc=1
  shift 2
  "$@" -LE "realtime|alone" || rc=1
  exit $rc' beside "$FUZZ_BUILD" "$FUZZ_SECONDS" "${CTEST[@]}" >"$BESIDE_LOG" 2>&1 &
beside=$!
set +m
trap 'kill -TERM -- -"$beside" 2>/dev/null; kill -TERM "${flying:-}" 2>/dev/null; exit 130' INT TERM

echo "test: the fuzzers and the tests not labelled realtime run beside these, at low priority ($BESIDE_LOG)"
# The cases on autopilot firmware run one at a time (RUN_SERIAL, fixed ports) and use about
# one core; the cases that fly a sim-vehicle, light and on ports of their own, run one at a
# time beside them. Then every other real-time case.
"${CTEST[@]}" "${RETRY[@]}" -L realtime -LE alone -R "$FLYING" -j 1 >"$FLYING_LOG" 2>&1 &
flying=$!
"${CTEST[@]}" "${RETRY[@]}" -L realtime -LE alone -R "$SITL"
realtime_rc=$?
wait "$flying" || realtime_rc=1
echo
echo "test: the real-time cases that fly a sim-vehicle, as they ran beside the SITL cases:"
cat "$FLYING_LOG"
"${CTEST[@]}" "${RETRY[@]}" -L realtime -LE alone -E "$SITL|$FLYING" || realtime_rc=1
wait "$beside"
beside_rc=$?
trap - INT TERM

echo
echo "test: the fuzzers and the tests not labelled realtime, as they ran beside the real-time ones:"
cat "$BESIDE_LOG"
echo
verdict() { [ "$1" -eq 0 ] && echo "test: $2 passed" || echo "test: $2 FAILED (above)"; }
verdict "$alone_rc" "tests run alone"
verdict "$realtime_rc" "real-time tests"
verdict "$beside_rc" "fuzzers and other tests"
[ "$alone_rc" -eq 0 ] && [ "$realtime_rc" -eq 0 ] && [ "$beside_rc" -eq 0 ]
