"""eamos.load_trace: a trace file as records (checked against docs/trace.md) and, with pandas,
as a DataFrame."""

import json
import os
import subprocess
import sys

import pytest

import eamos
from conftest import LISTING2


def test_a_trace_of_eamos_run_loads_as_records(cli_listing2):
    path = cli_listing2["trace"]
    lines = [json.loads(line) for line in path.read_text().splitlines()]
    t = eamos.load_trace(path)
    assert t.header == lines[0] and t.events == lines[1:] and len(t) == len(lines) - 1
    assert t.header["mission"] == "listing2.eamos"
    assert t.drones == ["Drone1", "Drone2", "Drone3"]
    assert t.outcome == "completed"
    starts = t.of("start", "Drone2")
    assert [e["name"] for e in starts[:3]] == ["Arm", "Takeoff", "Orbit"]
    assert all(e["drone"] == "Drone2" and e["line"] > 0 for e in starts)
    assert list(t) == t.events


def test_a_trace_loads_as_a_dataframe_one_row_per_event(cli_listing2):
    t = eamos.load_trace(cli_listing2["trace"])
    df = t.to_dataframe()
    assert len(df) == len(t)
    assert {"t", "event", "drone", "name", "line", "x", "z"} <= set(df.columns)
    assert list(df["event"]) == [e["event"] for e in t.events]
    tele = t.to_dataframe("telemetry")
    assert set(tele["event"]) == {"telemetry"} and len(tele) == len(t.of("telemetry"))
    # Drone2 takes off to 10 m: its highest telemetry sample is there.
    assert tele[tele["drone"] == "Drone2"]["z"].max() == pytest.approx(10, abs=0.3)
    assert tele["t"].is_monotonic_increasing


def test_without_pandas_to_dataframe_says_what_to_install_and_records_still_load(cli_listing2):
    # pandas is optional: a Python without it imports eamos and loads traces.
    code = (
        "import sys; sys.modules['pandas'] = None\n"
        "import eamos\n"
        f"t = eamos.load_trace({str(cli_listing2['trace'])!r})\n"
        "print(len(t))\n"
        "try:\n"
        "    t.to_dataframe()\n"
        "except ImportError as e:\n"
        "    print(e)\n"
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=os.environ, timeout=60)
    assert p.returncode == 0, p.stderr
    count, message = p.stdout.splitlines()
    assert int(count) == len(eamos.load_trace(cli_listing2["trace"]))
    assert "install python3-pandas" in message


def test_a_broken_trace_lists_every_problem_at_its_line(tmp_path, cli_listing2):
    lines = cli_listing2["trace"].read_text().splitlines()
    broken = list(lines)
    broken[3] = "{not json"
    event = json.loads(broken[5])
    event["t"] = -1
    broken[5] = json.dumps(event)
    path = tmp_path / "broken.jsonl"
    path.write_text("\n".join(broken[:-1]) + "\n")  # and no mission end
    with pytest.raises(eamos.TraceError) as e:
        eamos.load_trace(path)
    errors = e.value.errors
    assert errors[0] == f"{path}:4: error: not a JSON object"
    assert any(err.startswith(f"{path}:6: error:") and "negative" in err for err in errors)
    assert errors[-1].startswith(f"{path}:{len(lines) - 1}: error:") and "mission's end" in errors[-1]
    assert str(e.value) == "\n".join(errors)


def test_a_mission_file_given_as_a_trace_is_named_as_not_a_trace():
    with pytest.raises(eamos.TraceError) as e:
        eamos.load_trace(LISTING2)
    assert e.value.errors == [f"{LISTING2}:1: error: not a trace: its first line is not a JSON object; give the "
                              "JSON Lines file that `eamos run --trace FILE` (or eamos.run(..., trace=FILE)) wrote"]


def test_a_missing_trace_file_is_a_trace_error(tmp_path):
    with pytest.raises(eamos.TraceError, match="cannot read the trace: No such file"):
        eamos.load_trace(tmp_path / "none.jsonl")
    # A TraceError is a ValueError: code that catches bad input broadly catches it.
    assert issubclass(eamos.TraceError, ValueError)


def test_a_trace_written_by_the_module_loads_and_matches_its_callback(tmp_path):
    events = []
    path = tmp_path / "run.jsonl"
    eamos.run(LISTING2, on_event=events.append, trace=path, telemetry_hz=2)
    t = eamos.load_trace(path)
    assert t.events == events and t.header["telemetry_hz"] == 2
