#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (AddressSanitizer + UBSan) in their own build
# folder and runs each for a bounded time, seeded with the examples and test missions.
# Usage: scripts/fuzz.sh BUILD_DIR SECONDS_PER_TARGET
set -euo pipefail
BUILD=${1:-build-fuzz}
SECONDS_PER_TARGET=${2:-20}
cd "$(dirname "$0")/.."

if [ ! -f "$BUILD/build.ninja" ]; then
  CC=clang CXX=clang++ cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_UNITY_BUILD=ON \
    -DEAMOS_FUZZ=ON -DEAMOS_TESTS=OFF -DEAMOS_BENCH=OFF >/dev/null
fi
targets=(fuzz_frontend fuzz_fleet fuzz_mavlink fuzz_mission fuzz_wire fuzz_lsp fuzz_trace)
seeds=("examples/*.eamos tests/lang/diagnostics/*.eamos" "tests/fleet/data/*.yaml examples/*.yaml"
       "tests/fuzz/mavlink-seeds/*" "tests/fuzz/mission-seeds/*" "tests/fuzz/wire-seeds/*" "tests/fuzz/lsp-seeds/*"
       "tests/fuzz/trace-seeds/*")
cmake --build "$BUILD" -j "$(nproc)" --target "${targets[@]}"

# One fuzzer per core at a time: each is one process on one core.
run() {
  local target=$1 seeds=$2
  local corpus="$BUILD/corpus-$target"
  mkdir -p "$corpus"
  cp $seeds "$corpus"/ 2>/dev/null || true
  # -rss_limit_mb and -timeout turn memory blow-ups and hangs into failures.
  "$BUILD/tests/fuzz/$target" -max_total_time="$SECONDS_PER_TARGET" -timeout=10 \
    -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 "$corpus" 2>"$BUILD/$target.log"
}

report() {
  local target=$1 rc=$2
  echo "fuzz: $target for ${SECONDS_PER_TARGET}s"
  if [ "$rc" -ne 0 ]; then
    tail -40 "$BUILD/$target.log"
    echo "fuzz: $target FAILED (log: $BUILD/$target.log)"
    return 1
  fi
  grep -E "stat::number_of_executed_units|Done" "$BUILD/$target.log" | tail -2
}

pid=()
failed=0
reported=0
# Waits for the oldest fuzzer not yet reported, so the reports come in the targets' order.
report_next() {
  local rc=0
  wait "${pid[$reported]}" || rc=$?
  report "${targets[$reported]}" "$rc" || failed=1
  reported=$((reported + 1))
}
for i in "${!targets[@]}"; do
  run "${targets[$i]}" "${seeds[$i]}" &
  pid[$i]=$!
  if [ $((i + 1 - reported)) -ge "$(nproc)" ]; then report_next; fi
done
while [ "$reported" -lt "${#targets[@]}" ]; do report_next; done
[ "$failed" -eq 0 ] || exit 1
echo "fuzz: every target ran without a crash, hang or leak"
