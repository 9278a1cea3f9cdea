#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UBSan) in their own build
# folder and runs each for a bounded time, seeded with the examples and test missions.
# Usage: scripts/fuzz.sh BUILD_DIR SECONDS_PER_TARGET
set -euo pipefail
BUILD=${1:-build-fuzz}
SECONDS_PER_TARGET=${2:-20}
cd "$(dirname "$0")/.."

if [ ! -f "$BUILD/build.ninja" ]; then
  CC=clang CXX=clang++ cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DEAMOS_FUZZ=ON -DEAMOS_TESTS=OFF -DEAMOS_BENCH=OFF >/dev/null
fi
cmake --build "$BUILD" -j "$(nproc)" --target fuzz_frontend fuzz_fleet fuzz_mavlink fuzz_mission fuzz_wire

run() {
  local target=$1 seeds=$2
  local corpus="$BUILD/corpus-$target"
  mkdir -p "$corpus"
  cp $seeds "$corpus"/ 2>/dev/null || true
  echo "fuzz: $target for ${SECONDS_PER_TARGET}s"
  # -rss_limit_mb and -timeout turn memory blow-ups and hangs into failures.
  "$BUILD/tests/fuzz/$target" -max_total_time="$SECONDS_PER_TARGET" -timeout=10 \
    -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 "$corpus" 2>"$BUILD/$target.log" || {
      tail -40 "$BUILD/$target.log"
      echo "fuzz: $target FAILED (log: $BUILD/$target.log)"
      exit 1
    }
  grep -E "stat::number_of_executed_units|Done" "$BUILD/$target.log" | tail -2
}

run fuzz_frontend "examples/*.eamos tests/lang/diagnostics/*.eamos"
run fuzz_fleet "tests/fleet/data/*.yaml examples/*.yaml"
run fuzz_mavlink "tests/fuzz/mavlink-seeds/*"
run fuzz_mission "tests/fuzz/mission-seeds/*"
run fuzz_wire "tests/fuzz/wire-seeds/*"
echo "fuzz: every target ran without a crash, hang or leak"
