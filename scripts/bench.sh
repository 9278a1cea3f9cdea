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
# Pre-flight verification: Listing 2's paths, one stress path, the 100-drone squads' 64 paths
# (one flight at a time, then one per core) and the 100-drone show (about 25 s of CPU a repetition).
"$BUILD/bench/bench_verify" --benchmark_out=out/bench/verify.json --benchmark_out_format=json \
  --benchmark_repetitions=${REPS:-5} --benchmark_report_aggregates_only=true

# `eamos run` of a 1,000-drone show (50 fleet-wide barriers) and of 1,000 drones in squads:
# the whole process (compile and load included), CPU = user + sys, real-time factor = mission
# seconds per CPU second.
"$BUILD/src/cli/eamos" gen-stress --shape show --drones 1000 --work 1 --nodes 52000 -o out/bench/show-1000.eamos
"$BUILD/src/cli/eamos" gen-stress --nodes 100000 --drones 1000 -o out/bench/squads-1000.eamos
for m in show-1000 squads-1000; do
  /usr/bin/time -f '%U %S %M' -o out/bench/$m.time "$BUILD/src/cli/eamos" run out/bench/$m.eamos > out/bench/$m.log
  awk -v m="$m" -v t="$(sed -n 's/^mission completed in \([0-9.]*\) s.*/\1/p' out/bench/$m.log)" \
    '{ printf "run %s: %.1f mission s in %.2f CPU s (%.0fx real time), %d MB peak\n", m, t, $1 + $2, t / ($1 + $2), $3 / 1000 }' \
    out/bench/$m.time
done | tee out/bench/run-1000.txt

# Distributed execution. Cross-drone trigger latency through eamos's DDS
# transport and event loops, then ddsperf ping/pong on the same loopback configuration in
# the same run (ddsperf prints RTT/2).
"$BUILD/bench/bench_dds_latency" --benchmark_out=out/bench/dds_latency.json --benchmark_out_format=json
export CYCLONEDDS_URI="file://$PWD/config/cyclonedds-loopback.xml"
timeout 12 ddsperf -i 63 pong > /dev/null 2>&1 &
timeout 10 ddsperf -i 63 -D 5 ping 2>&1 | grep -E ' size 12 ' | tail -3 | tee out/bench/ddsperf.txt
wait || true
unset CYCLONEDDS_URI

# DEX process start to READY (the ground prints it), and Listing 2 in real time: in one
# process, and as four processes (three DEXes and the ground).
"$BUILD/src/cli/eamos" compile -q examples/listing2.eamos -o out/bench/listing2-deploy
"$BUILD/src/cli/eamos" launch out/bench/listing2-deploy --domain 64 --speed 10 | grep 'ready (' | tee out/bench/ready.txt
{
  /usr/bin/time -f 'in-process  real time: %e s wall, %M KB peak' \
    "$BUILD/src/cli/eamos" run -q examples/listing2.eamos --realtime | tail -1
  /usr/bin/time -f 'distributed real time: %e s wall (ground process), %M KB peak (ground)' \
    "$BUILD/src/cli/eamos" run -q examples/listing2.eamos --distributed --domain 65 | tail -1
} 2>&1 | tee out/bench/listing2-realtime.txt
echo "bench: results in out/bench/"
