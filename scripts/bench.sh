#!/usr/bin/env bash
# Runs the benchmarks and writes their JSON next to a console table.
set -euo pipefail
BUILD=${1:-build}
cd "$(dirname "$0")/.."
mkdir -p out/bench
"$BUILD/bench/bench_compile" --benchmark_out=out/bench/compile.json --benchmark_out_format=json \
  --benchmark_repetitions=${REPS:-3} --benchmark_report_aggregates_only=true
echo "bench: results in out/bench/"
