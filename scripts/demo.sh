#!/usr/bin/env bash
# The main job (make demo): Listing 2 through every stage, into out/listing2/. Check and
# compile it into deployment folders, render its AMT, MEG and each drone's MDG as SVG, fly it
# in the simulator (trace, summary, picture), verify every example, fly the deployment as one
# DEX process per drone over Cyclone DDS, and print how to replay the run in the browser.
set -euo pipefail
BUILD=${1:-build}
EAMOS="$BUILD/src/cli/eamos"
MISSION=examples/listing2.eamos
OUT=out/listing2

mkdir -p "$OUT/graphs"
"$EAMOS" check "$MISSION"
"$EAMOS" compile -q "$MISSION" -o "$OUT/deploy"
"$EAMOS" graph -q "$MISSION" --kind amt --format svg -o "$OUT/graphs/amt.svg"
"$EAMOS" graph -q "$MISSION" --kind meg --format svg -o "$OUT/graphs/meg.svg"
for drone in Drone1 Drone2 Drone3; do
  "$EAMOS" graph -q "$MISSION" --kind mdg --drone "$drone" --format svg -o "$OUT/graphs/mdg-$drone.svg"
done
"$EAMOS" stats "$MISSION" -o "$OUT/stats.json" -q
"$EAMOS" run "$MISSION" -q --fleet examples/listing2-right.yaml \
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
"$EAMOS" launch "$OUT/deploy" --speed 5 --domain 3 \
  --trace "$OUT/distributed-trace.jsonl" --summary "$OUT/distributed-summary.json"
echo
echo "demo: deployment in $OUT/deploy/, graphs in $OUT/graphs/, statistics in $OUT/stats.json,"
echo "      trace in $OUT/trace.jsonl, summary in $OUT/summary.json, picture of the run in $OUT/plot.svg,"
echo "      the distributed run's trace in $OUT/distributed-trace.jsonl (DEX logs: $OUT/deploy/<drone>/dex.log)"
ls "$OUT/deploy" "$OUT/graphs"
echo
echo "watch the run replay in the browser (docs/monitor.md): open the URL this prints"
echo "  $EAMOS monitor $OUT/trace.jsonl --mission $MISSION --fleet examples/listing2-right.yaml"
