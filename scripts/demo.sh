#!/usr/bin/env bash
# The main job (make demo): Listing 2 through every stage, into out/listing2/. Check and
# compile it with its fleet into deployment folders, render its AMT, MEG and each drone's MDG
# as SVG, fly it in the simulator (trace, summary, picture), verify every example, fly the
# same deployment as one DEX process per drone over Cyclone DDS, check from both traces that
# the two runs flew the same mission down the same branch, and print how to replay the run in
# the browser.
set -euo pipefail
BUILD=${1:-build}
EAMOS="$BUILD/src/cli/eamos"
MISSION=examples/listing2.eamos
# Drone1's Sensor1 reads 120: the If (Drone1.Sensor1() >= 100) takes SEQ_go_right. The one
# fleet goes into the deployment and into the in-process run alike.
FLEET=examples/listing2-right.yaml
OUT=out/listing2

mkdir -p "$OUT/graphs"
"$EAMOS" check "$MISSION" --fleet "$FLEET"
"$EAMOS" compile -q "$MISSION" --fleet "$FLEET" -o "$OUT/deploy"
"$EAMOS" graph -q "$MISSION" --kind amt --format svg -o "$OUT/graphs/amt.svg"
"$EAMOS" graph -q "$MISSION" --kind meg --format svg -o "$OUT/graphs/meg.svg"
for drone in Drone1 Drone2 Drone3; do
  "$EAMOS" graph -q "$MISSION" --kind mdg --drone "$drone" --format svg -o "$OUT/graphs/mdg-$drone.svg"
done
"$EAMOS" stats "$MISSION" -o "$OUT/stats.json" -q
echo
echo "demo: flying the deployment in one process (the built-in simulator, virtual time)"
"$EAMOS" run "$MISSION" -q --fleet "$FLEET" \
  --trace "$OUT/trace.jsonl" --summary "$OUT/summary.json" --plot "$OUT/plot.svg"
# Pre-flight verification of every example (docs/verify.md); Listing 2 with its sensor's
# range and timing perturbations finds Drone2 landing beside a parked drone (explained there).
echo
for mission in examples/patrol.eamos examples/relay.eamos examples/survey.eamos; do
  "$EAMOS" verify -q "$mission" --jitter
done
"$EAMOS" verify -q "$MISSION" --fleet examples/listing2-range.yaml --jitter \
  --plot "$OUT/verify.svg" --json > "$OUT/verify.json" || echo "verify: Listing 2's findings in $OUT/verify.json and $OUT/verify.svg"
# The same deployment as separate processes: one DEX per drone over Cyclone DDS (loopback),
# started together by the ground process, five times faster than real time.
echo
echo "demo: flying the same deployment as one DEX process per drone over Cyclone DDS (5x real time)"
"$EAMOS" launch "$OUT/deploy" --speed 5 --domain 3 \
  --trace "$OUT/distributed-trace.jsonl" --summary "$OUT/distributed-summary.json"
# Both traces name the compiled mission (its hash) and hold the If's decision.
mission_hash() { head -1 "$1" | grep -o '"mission_hash":"[0-9a-f]*"' | cut -d'"' -f4; }
branch() {
  grep '"event":"condition"' "$1" | grep -F 'Drone1.Sensor1() >= 100' | grep -o '"value":[a-z]*' | head -1 | cut -d: -f2
}
in_process_hash=$(mission_hash "$OUT/trace.jsonl")
distributed_hash=$(mission_hash "$OUT/distributed-trace.jsonl")
in_process_branch=$(branch "$OUT/trace.jsonl")
distributed_branch=$(branch "$OUT/distributed-trace.jsonl")
echo
if [ -n "$in_process_hash" ] && [ "$in_process_hash" = "$distributed_hash" ] &&
   [ -n "$in_process_branch" ] && [ "$in_process_branch" = "$distributed_branch" ]; then
  side=$([ "$in_process_branch" = true ] && echo "SEQ_go_right" || echo "SEQ_go_left")
  echo "demo: in one process and distributed, the same deployment (mission ${in_process_hash:0:12}…, fleet $FLEET)"
  echo "      flew the same branch: Drone1.Sensor1() >= 100 was $in_process_branch in both, so both flew $side"
else
  echo "demo: the two runs differ: mission ${in_process_hash:-?} / ${distributed_hash:-?}," \
       "Drone1.Sensor1() >= 100 ${in_process_branch:-?} / ${distributed_branch:-?}" >&2
  exit 1
fi
echo
echo "demo: deployment in $OUT/deploy/, graphs in $OUT/graphs/, statistics in $OUT/stats.json,"
echo "      trace in $OUT/trace.jsonl, summary in $OUT/summary.json, picture of the run in $OUT/plot.svg,"
echo "      the distributed run's trace in $OUT/distributed-trace.jsonl (DEX logs: $OUT/deploy/<drone>/dex.log)"
ls "$OUT/deploy" "$OUT/graphs"
echo
echo "watch the run replay in the browser (docs/monitor.md): open the URL this prints"
echo "  $EAMOS monitor $OUT/trace.jsonl"
