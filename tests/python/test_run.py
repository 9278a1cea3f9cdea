"""eamos.run / Compilation.run: the simulator run of `eamos run`, in this process, with a
callback per trace event."""

import json
import os
import signal
import subprocess
import sys
import warnings

import pytest

import eamos
from conftest import LISTING2, run_eamos


def trace_lines(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


def test_listing2_completes_with_the_duration_states_and_trace_of_eamos_run(tmp_path, cli_listing2):
    trace = tmp_path / "py.jsonl"
    r = eamos.run(LISTING2, trace=trace)
    summary = cli_listing2["summary"]
    assert r.completed and summary["status"] == "completed"
    assert r.duration == summary["duration"] and r.duration > 10
    assert r.failure is None and r.error == ""
    assert list(r.drones) == list(summary["drones"])
    for name, d in r.drones.items():
        cli = summary["drones"][name]
        assert d.final
        assert (d.state["x"], d.state["y"], d.state["z"]) == (cli["x"], cli["y"], cli["z"])
        assert (d.state["armed"], d.state["landed"]) == (False, True)
        assert d.state["pictures"] == cli["pictures"]
        # The track starts on the ground at home, climbs, and ends down again.
        assert d.track["z"][0] == 0 and max(d.track["z"]) >= 2.7 and d.track["z"][-1] == 0
        assert len(set(map(len, d.track.values()))) == 1 and d.track["t"] == sorted(d.track["t"])
    # The trace is the one `eamos run --trace` writes, byte for byte.
    assert trace.read_text() == cli_listing2["trace"].read_text()


def test_the_callback_receives_every_event_of_the_trace_in_order(tmp_path):
    events = []
    trace = tmp_path / "t.jsonl"
    r = eamos.compile(LISTING2).run(events.append, trace=trace)
    assert r.completed
    lines = trace_lines(trace)
    assert lines[0]["event"] == "header"
    assert events == lines[1:]
    kinds = {e["event"] for e in events}
    assert {"start", "end", "condition", "node", "telemetry", "message", "mission"} <= kinds
    assert events[-1]["event"] == "mission" and events[-1]["outcome"] == "completed"
    assert events[-1]["t"] == r.duration


def test_without_telemetry_the_callback_gets_no_telemetry_and_the_run_is_the_same():
    events = []
    r = eamos.run(LISTING2, on_event=events.append, telemetry_hz=0)
    assert r.completed and r.duration == eamos.run(LISTING2).duration
    assert events and not [e for e in events if e["event"] == "telemetry"]


def test_a_callback_that_raises_ends_the_mission_and_its_exception_comes_back(tmp_path):
    seen = []

    class Stop(Exception):
        pass

    def on_event(e):
        seen.append(e)
        if e["event"] == "start" and e["name"] == "Takeoff":
            raise Stop("enough")

    trace = tmp_path / "t.jsonl"
    with pytest.raises(Stop, match="enough"):
        eamos.run(LISTING2, on_event=on_event, trace=trace)
    # The mission was abandoned at that event, and says why.
    end = eamos.load_trace(trace).events[-1]
    assert (end["outcome"], end["reason"]) == ("failed", "the on_event callback raised Stop: enough")
    assert end["t"] == seen[-1]["t"]
    # Not called again after it raised: the mission was abandoned at that event.
    assert seen[-1]["event"] == "start" and seen[-1]["name"] == "Takeoff"
    assert not [e for e in seen if e["event"] == "mission"]


def test_without_tracks_each_drone_keeps_its_first_and_last_state_and_the_run_is_the_same():
    whole = eamos.run(LISTING2)
    short = eamos.run(LISTING2, tracks=False)
    assert short.completed and short.duration == whole.duration
    for name, d in short.drones.items():
        full = whole.drones[name].track
        assert d.track == {k: [v[0], v[-1]] for k, v in full.items()} and len(full["t"]) > 50


def test_a_failed_action_fails_the_run_with_the_responsible_line():
    # Takeoff without Arm (armed only above 100 % battery, never): the simulated drone refuses it.
    c = eamos.compile_text("var Drone1 Quad\nfunc INIT() { SEQ_fly() }\nfunc SEQ_fly() {\n"
                           "  If(Drone1.Battery() > 100, SEQ_arm, SEQ_stay)\n  Drone1.Takeoff(3)\n}\n"
                           "func SEQ_arm() { Drone1.Arm() }\nfunc SEQ_stay() { PauseFor(0) }\n",
                           name="disarmed.eamos")
    events = []
    r = c.run(events.append)
    assert not r.completed
    assert r.failure is not None
    assert (r.failure.drone, r.failure.action, r.failure.line, r.failure.kind) == ("Drone1", "Takeoff", 5, "refused")
    assert "Takeoff (line 5) failed" in r.error
    assert (events[-1]["event"], events[-1]["outcome"]) == ("mission", "failed")


def test_a_mission_still_flying_at_the_time_limit_fails_and_says_so():
    r = eamos.run(LISTING2, time_limit=5)
    assert not r.completed and r.duration == 5
    assert "did not complete within 5 s" in r.error
    # Every drone was brought down by its failsafe before the run returned.
    assert all(d.state["landed"] for d in r.drones.values())


@pytest.mark.parametrize("options, error, words", [
    ({"time_limit": 0}, ValueError, "time_limit must be a positive"),
    ({"time_limit": float("nan")}, ValueError, "time_limit must be a positive"),
    ({"telemetry_hz": -1}, ValueError, "telemetry_hz must be 0"),
    ({"speed": 0}, ValueError, "speed must be a positive"),
    ({"on_event": 42}, TypeError, "on_event must be a callable"),
    ({"trace": "/nonexistent-dir/t.jsonl"}, ValueError, "cannot write trace '/nonexistent-dir/t.jsonl'"),
])
def test_bad_options_are_refused_before_anything_flies(options, error, words):
    events = []
    on_event = options.pop("on_event", events.append)
    with pytest.raises(error, match=words):
        eamos.run(LISTING2, on_event=on_event, **options)
    assert events == []


def test_a_run_at_a_speed_the_host_cannot_follow_warns_that_its_timing_is_not_the_plans():
    # A wall microsecond is a mission second at 1e6: no host follows that.
    with pytest.warns(RuntimeWarning, match=r"could not keep up with speed=1e\+06: events ran up to [0-9.]+ s"):
        r = eamos.run(LISTING2, speed=1e6, telemetry_hz=0)
    assert r.max_lag > 0.1
    assert eamos.run(LISTING2, telemetry_hz=0).max_lag == 0.0


def test_a_completed_run_that_leaves_a_drone_in_the_air_or_armed_warns_as_eamos_run_does():
    c = eamos.compile_text("var A Quad\nvar B Quad\nfunc INIT() { PAR_x() }\nfunc PAR_x() { SEQ_a(); SEQ_b() }\n"
                           "func SEQ_a() { A.Arm(); A.Takeoff(5) }\nfunc SEQ_b() { B.Arm(); B.Takeoff(5); B.Land() }\n")
    with pytest.warns(RuntimeWarning) as seen:
        r = c.run(telemetry_hz=0)
    assert r.completed
    messages = [str(w.message) for w in seen]
    assert any(m.startswith("A is still in the air when the mission ends (z = 5.0 m)") for m in messages), messages
    assert any(m.startswith("B is still armed on the ground when the mission ends") for m in messages), messages
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # Listing 2 ends with every drone down and disarmed: no warning
        assert eamos.run(LISTING2, telemetry_hz=0).completed


def test_a_fleet_file_changes_the_flight_as_it_does_for_eamos_run(tmp_path, eamos_bin):
    fleet = LISTING2.parent / "listing2-right.yaml"
    summary = tmp_path / "s.json"
    run_eamos(eamos_bin, "run", "-q", LISTING2, "--fleet", fleet, "--summary", summary)
    cli = json.loads(summary.read_text())
    r = eamos.run(LISTING2, fleet=fleet)
    assert r.completed and r.duration == cli["duration"]
    # Sensor1 reads 120 here: Drone1 takes the right branch, 5 m east of its home.
    assert r.drones["Drone1"].state["x"] == cli["drones"]["Drone1"]["x"] == pytest.approx(5, abs=0.5)


@pytest.mark.realtime
def test_ctrl_c_during_a_run_lands_every_drone_and_raises_keyboard_interrupt(tmp_path):
    # A real-time run at 20x, without a callback, in its own process, writing its trace into a
    # pipe: the signal is sent once the first part of the trace has come through (the flight
    # is under way), as a notebook's Interrupt would be. The rest of the trace then shows how
    # the run ended.
    pipe = tmp_path / "trace.pipe"
    os.mkfifo(pipe)
    code = (
        "import eamos\n"
        "try:\n"
        f"    eamos.run({str(LISTING2)!r}, speed=20, trace={str(pipe)!r})\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted')\n"
    )
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        with open(pipe) as f:
            text = f.readline()
            p.send_signal(signal.SIGINT)
            text += f.read()
        out, err = p.communicate(timeout=60)
    finally:
        p.kill()
    assert p.returncode == 0, err
    assert out == "interrupted\n"
    trace = tmp_path / "trace.jsonl"
    trace.write_text(text)
    t = eamos.load_trace(trace)
    end = t.events[-1]
    assert end["outcome"] == "failed" and end["reason"] == "interrupted (KeyboardInterrupt)"
    assert end["t"] < 16.7
    # The drones in the air ran their failsafe (land) and were down when run() returned.
    assert t.of("failsafe") and {e["name"] for e in t.of("failsafe")} == {"land"}
    for name in t.drones:
        last = t.of("telemetry", name)[-1]
        assert last["landed"] and last["z"] == pytest.approx(0, abs=0.05)
