#!/usr/bin/env bash
# Builds the project under the sanitizers, each in a tree of its own (clang, -O1 -g1, no
# benchmarks or fuzzers, only the executables its tests need), and runs:
#   address: the unit and in-process suites (every case not labelled realtime or alone), the
#            MAVLink cases that fly a sim-vehicle, and the monitor's and the signal watcher's
#            suites under AddressSanitizer and UndefinedBehaviorSanitizer, leaks included;
#   thread:  the threaded suites under ThreadSanitizer: the MAVLink link and its receive thread
#            (tests/mavlink*, tests/sim_vehicle), Cyclone DDS calling back from its own threads
#            (test_transport and four Distributed cases of real `eamos launch` runs), the
#            monitor's live server, the signal watcher of `eamos run`, and `eamos verify`
#            flying a path's timings on several threads (test_verify_explore).
# Every process the tests start (eamos, its DEXes, sim-vehicles) is instrumented too. A report
# from any of them fails the run, whatever its exit status did to the test: the sanitizers
# write each report to a file in the tree's sanitizer-logs/, which must stay empty.
# Usage: scripts/sanitize.sh [address|thread|all|prebuild] [BUILD_PREFIX]   (default: all build)
set -uo pipefail
WHICH=${1:-all}
PREFIX=${2:-build}
cd "$(dirname "$0")/.."
ROOT=$(pwd)
JOBS=$(nproc)

# The test executables each tree builds; ctest lists the others as `<target>_NOT_BUILT`,
# which every run leaves out.
ASAN_TESTS=(test_fleet test_lang test_graph test_deploy test_cli test_progress test_failure_reasons
            test_dex test_mid test_sim test_verify test_verify_sweep test_verify_explore test_mavlink test_mavlink_adapter
            test_mavlink_listing2 test_mavlink_failure_reasons test_mavlink_attacker
            test_sim_vehicle test_transport test_monitor test_interrupt test_lsp test_failsafe)
TSAN_TESTS=(test_mavlink test_mavlink_adapter test_sim_vehicle test_mavlink_listing2
            test_mavlink_failure_reasons test_mavlink_attacker test_transport test_distributed
            test_monitor test_interrupt test_verify_explore)
# Real-time cases, after the other cases and the TSan build, with nothing beside them: the
# MAVLink cases that fly a sim-vehicle on the wall clock (two at a time, as in make test), then
# one at a time the monitor's input checks and live server and the signal watcher of `eamos
# run`; under TSan also four Distributed cases: a mission that completes, one that fails on one
# drone, a DEX killed and one stopped by SIGTERM (the liveliness and signal paths). As in make
# test, a real-time case that fails runs once more, and only a real-time case.
FLYING='^(Mavlink|HostileVehicle|SimVehicle)'
ASAN_REALTIME='^(Monitor|Interrupt)'
TSAN_REALTIME='^(Monitor|Interrupt|Distributed\.(Listing2Right|FailedActionOnOneDrone|KilledDex|SigtermOnADex))'

# Every time, so a tree configured before keeps the options this script needs (no Python
# module, benchmarks or fuzzers); on an existing tree it takes seconds.
configure() {  # tree, sanitizer
  CC=clang CXX=clang++ cmake -S . -B "$1" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_UNITY_BUILD=ON \
    -DEAMOS_SANITIZE="$2" -DEAMOS_BENCH=OFF -DEAMOS_FUZZ=OFF -DEAMOS_PYTHON=OFF >/dev/null
}

# Prints every report the sanitizers wrote and fails if there is one.
reports() {  # tree, what
  local logs=("$1"/sanitizer-logs/*)
  [ -e "${logs[0]}" ] || return 0
  for f in "${logs[@]}"; do echo "== $f"; cat "$f"; done
  echo "sanitize: $2: ${#logs[@]} process(es) with sanitizer reports, above"
  return 1
}

build() {  # tree, sanitizer, targets...
  local tree=$1 sanitizer=$2 start=$SECONDS
  shift 2
  configure "$tree" "$sanitizer" && cmake --build "$tree" -j "$JOBS" --target eamos "$@" || return 1
  echo "sanitize: $sanitizer: build $((SECONDS - start)) s"
}

# The cases of a tree that are not real-time, two at a time.
test_others() {  # tree
  rm -rf "$1/sanitizer-logs"
  mkdir -p "$1/sanitizer-logs"
  ctest --test-dir "$1" --output-on-failure -E _NOT_BUILT -j "$JOBS" -LE "realtime|alone"
}

# Its real-time cases; then every report of both runs.
test_realtime() {  # tree, sanitizer, realtime regex
  local rc=0
  local retry=(--repeat until-pass:2)
  ctest --test-dir "$1" --output-on-failure -E _NOT_BUILT -L realtime -R "$FLYING" -j "$JOBS" "${retry[@]}" || rc=1
  ctest --test-dir "$1" --output-on-failure -E _NOT_BUILT -L realtime -R "$3" "${retry[@]}" || rc=1
  reports "$1" "$2" || rc=1
  return $rc
}

asan() {  # command...: with the options of the ASan runs
  local logs=$ROOT/$PREFIX-asan/sanitizer-logs
  # exitcode 66: not the 1 of a refused mission, so no test that expects a refusal can pass on
  # a sanitizer's exit. LeakSanitizer (part of ASan) makes a leak in any process a finding.
  ASAN_OPTIONS="log_path=$logs/asan:exitcode=66:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1" \
  UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
  LSAN_OPTIONS="suppressions=$ROOT/tests/sanitizers/lsan.supp:print_suppressions=0" "$@"
}

tsan() {  # command...: with the options of the TSan runs
  local logs=$ROOT/$PREFIX-tsan/sanitizer-logs
  # ignore_noninstrumented_modules: Cyclone DDS and the other Debian libraries are not built
  # with TSan (tests/sanitizers/tsan.supp says why this, and not a suppression per library).
  TSAN_OPTIONS="log_path=$logs/tsan:exitcode=66:second_deadlock_stack=1:ignore_noninstrumented_modules=1:suppressions=$ROOT/tests/sanitizers/tsan.supp" "$@"
}

run_address() {
  build "$PREFIX-asan" address "${ASAN_TESTS[@]}" || return 1
  local rc=0
  asan test_others "$PREFIX-asan" || rc=1
  asan test_realtime "$PREFIX-asan" address "$ASAN_REALTIME" || rc=1
  return $rc
}

run_thread() {
  build "$PREFIX-tsan" thread "${TSAN_TESTS[@]}" || return 1
  local rc=0
  tsan test_others "$PREFIX-tsan" || rc=1
  tsan test_realtime "$PREFIX-tsan" thread "$TSAN_REALTIME" || rc=1
  return $rc
}

# Both, in less time: the ASan cases that are not real-time wait on I/O and the wall clock
# more than they compute (about a third of a core), so the TSan tree builds beside them, at
# the lowest priority, as the fuzzers build beside the real-time tests in make test.
run_all() {
  build "$PREFIX-asan" address "${ASAN_TESTS[@]}" || return 1
  local rc=0 start=$SECONDS tsan_log=$PREFIX-asan/tsan-build.log
  echo "sanitize: the TSan tree builds beside the ASan cases ($tsan_log)"
  (renice -n 19 -p "$BASHPID" >/dev/null; build "$PREFIX-tsan" thread "${TSAN_TESTS[@]}") >"$tsan_log" 2>&1 &
  local builder=$!
  asan test_others "$PREFIX-asan" || rc=1
  echo "sanitize: address: cases that are not real-time $((SECONDS - start)) s"
  local built=0
  wait "$builder" || built=1
  tail -1 "$tsan_log"
  asan test_realtime "$PREFIX-asan" address "$ASAN_REALTIME" || rc=1
  if [ "$built" -ne 0 ]; then
    cat "$tsan_log"
    echo "sanitize: the TSan build FAILED (above)"
    return 1
  fi
  start=$SECONDS
  tsan test_others "$PREFIX-tsan" || rc=1
  tsan test_realtime "$PREFIX-tsan" thread "$TSAN_REALTIME" || rc=1
  echo "sanitize: thread: cases $((SECONDS - start)) s"
  return $rc
}

# Only the two trees' builds, no test: what scripts/test.sh runs beside make test's real-time
# cases for .ci/run (EAMOS_PREBUILD_SANITIZERS), stopped when they end.
prebuild() {
  build "$PREFIX-asan" address "${ASAN_TESTS[@]}" && build "$PREFIX-tsan" thread "${TSAN_TESTS[@]}"
}

rc=0
case "$WHICH" in
  prebuild) prebuild; exit $? ;;
  address) run_address || rc=1 ;;
  thread) run_thread || rc=1 ;;
  all) run_all || rc=1 ;;
  *) echo "usage: scripts/sanitize.sh [address|thread|all|prebuild] [BUILD_PREFIX]" >&2; exit 2 ;;
esac
[ "$rc" -eq 0 ] && echo "sanitize: $WHICH passed, no sanitizer report" || echo "sanitize: $WHICH FAILED (above)"
exit $rc
