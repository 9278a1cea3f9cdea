#!/usr/bin/env python3
"""Time per barrier of a run, from its trace (`eamos run|launch --trace T.jsonl`).

A barrier is one pass of the mission through a sync point (a PAR's fork) that drones
arrive at by messages: each drone's arrival is the instant it sent its trigger to the sync
point (`message` events, `sent`), and it continues when its clone of the sync point ends
(`node` events of kind `fork`, outcome `ended`). The time of a barrier is from the last
arrival to the last continuation: what the synchronisation itself costs, beside the wait
for the slowest drone. Times are mission seconds; with --speed X (the run's --speed) they
are also given as wall milliseconds. A sync point passed several times (in a loop) gives
one barrier per pass, matched in order.

    scripts/barrier-stats.py trace.jsonl [--speed X] [--json]
"""
import argparse
import json
import math
import sys
from collections import defaultdict


def read_events(path):
    events = []
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            try:
                events.append(json.loads(line))
            except json.JSONDecodeError as e:
                raise SystemExit(f"{path}:{number}:{e.colno}: error: not a JSON line ({e.msg}); "
                                 "give the trace `eamos run` or `eamos launch` wrote with --trace")
    return events


def barriers(events):
    """Per barrier (sync point, pass): (node, pass, last arrival, last continuation, drones)."""
    continues = defaultdict(lambda: defaultdict(list))  # node -> drone -> [t]
    arrivals = defaultdict(lambda: defaultdict(list))   # node -> sender -> [sent]
    for e in events:
        if not isinstance(e, dict):
            continue
        if e.get("event") == "node" and e.get("kind") == "fork" and e.get("outcome") == "ended" and \
                isinstance(e.get("t"), (int, float)) and "drone" in e and "node" in e:
            continues[e["node"]][e["drone"]].append(float(e["t"]))
    for e in events:
        if not isinstance(e, dict) or not isinstance(e.get("sent"), (int, float)) or "from" not in e:
            continue
        if e.get("event") == "message" and e.get("kind") == "trigger" and e.get("node") in continues:
            sent = round(float(e["sent"]), 6)
            mine = arrivals[e["node"]][e["from"]]
            if sent not in mine:  # one arrival, sent to every drone that waits there
                mine.append(sent)
    found = []
    for node, senders in arrivals.items():
        passes = max(len(v) for v in senders.values())
        for k in range(passes):
            arrived = [sorted(v)[k] for v in senders.values() if len(v) > k]
            went_on = [sorted(v)[k] for v in continues[node].values() if len(v) > k]
            if arrived and went_on:
                found.append((node, k, max(arrived), max(went_on), len(went_on)))
    return sorted(found, key=lambda b: b[2])


def percentile(values, p):
    """Nearest rank: the smallest value with at least p % of the values at or below it."""
    ordered = sorted(values)
    return ordered[max(0, math.ceil(p / 100 * len(ordered)) - 1)]


def summary(found, speed):
    times = [cont - last for (_, _, last, cont, _) in found]
    if not times:
        return {"barriers": 0}
    out = {"barriers": len(times), "drones_max": max(b[4] for b in found),
           "median_s": percentile(times, 50), "p99_s": percentile(times, 99), "max_s": max(times)}
    if speed:
        for key in ("median", "p99", "max"):
            out[key + "_wall_ms"] = out[key + "_s"] / speed * 1000
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("trace")
    parser.add_argument("--speed", type=float, default=1.0, help="the run's --speed (default 1)")
    parser.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    args = parser.parse_args()
    if not args.speed > 0:
        raise SystemExit("barrier-stats: error: --speed must be a number greater than 0")
    try:
        found = barriers(read_events(args.trace))
    except OSError as e:
        raise SystemExit(f"barrier-stats: error: cannot read {args.trace}: {e.strerror}")
    s = summary(found, args.speed)
    if args.json:
        print(json.dumps(s))
    elif s["barriers"] == 0:
        print("no barrier in this trace (no sync point that drones arrived at by messages)")
    else:
        print(f"{s['barriers']} barriers, up to {s['drones_max']} drones each; last arrival to last continuation: "
              f"median {s['median_wall_ms']:.1f} ms, p99 {s['p99_wall_ms']:.1f} ms, max {s['max_wall_ms']:.1f} ms "
              f"(wall, at --speed {args.speed:g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
