#!/usr/bin/env bash
# Runs the benchmarks and writes their JSON next to a console table, with the machine they
# ran on and the MDG sizes of the 5,000-node mission: what docs/performance.md reports.
set -euo pipefail
BUILD=${1:-build}
cd "$(dirname "$0")/.."
mkdir -p out/bench

build_type=$(grep '^CMAKE_BUILD_TYPE:' "$BUILD/CMakeCache.txt" | cut -d= -f2)
{
  echo "date:       $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo "cpus:       $(nproc) × $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')"
  echo "memory:     $(free -h | awk '/^Mem:/ {print $2}')"
  echo "os:         $(. /etc/os-release && echo "$PRETTY_NAME"), kernel $(uname -r)"
  echo "compiler:   $(c++ --version | head -1)"
  echo "build type: ${build_type:-RelWithDebInfo (the default of CMakeLists.txt)}"
} | tee out/bench/machine.txt

# The paper's second measurement: a 5,000-node, 20-drone mission; its largest drone MDG.
"$BUILD/src/cli/eamos" gen-stress --nodes 5000 --drones 20 -o out/bench/stress-5000.eamos
"$BUILD/src/cli/eamos" stats out/bench/stress-5000.eamos -o out/bench/stats-5000.json
awk '/"per_drone"/ {in_drones = 1} in_drones && /^        "nodes":/ {
       n = $2 + 0; if (n > max) max = n } END { print "largest drone MDG of the 5,000-node mission: " max " nodes" }' \
  out/bench/stats-5000.json | tee -a out/bench/machine.txt

"$BUILD/bench/bench_compile" --benchmark_out=out/bench/compile.json --benchmark_out_format=json \
  --benchmark_repetitions=${REPS:-5} --benchmark_report_aggregates_only=true
"$BUILD/bench/bench_dex" --benchmark_out=out/bench/dex.json --benchmark_out_format=json \
  --benchmark_repetitions=${REPS:-5} --benchmark_report_aggregates_only=true
echo "bench: results in out/bench/"
