"""eamos.compile / compile_text: diagnostics as objects at the right place, graphs as the data
`eamos graph --format json` writes."""

import json
import re

import pytest

import eamos
from conftest import LISTING2, ROOT, run_eamos

# Two errors on known lines: a capability the type lacks (line 4, column 10: `Fly`) and a drone
# nobody declared (line 5, column 3: `Drone9`).
BROKEN = """var Drone1 Quad
func INIT() { SEQ_fly() }
func SEQ_fly() {
  Drone1.Fly(3)
  Drone9.Land()
}
"""


def cli_positions(stderr):
    return [(int(m[1]), int(m[2]), m[3]) for m in re.finditer(r"^[^:\n]+:(\d+):(\d+): (error|warning|note):", stderr, re.M)]


def test_broken_mission_lists_every_error_at_its_line_and_column(tmp_path, eamos_bin):
    path = tmp_path / "broken.eamos"
    path.write_text(BROKEN)
    c = eamos.compile(path)
    assert not c.ok
    assert [(d.line, d.column, d.severity) for d in c.diagnostics] == [(4, 10, "error"), (5, 3, "error")]
    assert all(d.file == str(path) for d in c.diagnostics)
    assert "no capability 'Fly'" in c.diagnostics[0].message
    assert "Drone9" in c.diagnostics[1].message
    # The same places and words as `eamos check`; each diagnostic's text is its part of it.
    cli = run_eamos(eamos_bin, "check", path, expect=1)
    assert cli_positions(cli.stderr) == [(d.line, d.column, d.severity) for d in c.diagnostics]
    for d in c.diagnostics:
        assert d.text.startswith(f"{path}:{d.line}:{d.column}: error: {d.message}\n")
        assert d.text in cli.stderr
    assert c.text in cli.stderr


def test_compile_text_names_the_file_it_was_given_and_finds_the_same_errors(tmp_path):
    c = eamos.compile_text(BROKEN, name="inline.eamos")
    assert [(d.file, d.line, d.column) for d in c.errors] == [("inline.eamos", 4, 10), ("inline.eamos", 5, 3)]
    assert str(c.errors[0]).startswith("inline.eamos:4:10: error:")


def test_graphs_of_a_mission_that_did_not_compile_raise_its_diagnostics():
    c = eamos.compile_text(BROKEN, name="inline.eamos")
    with pytest.raises(eamos.CompileError) as e:
        c.meg
    assert "inline.eamos:4:10: error:" in str(e.value)
    assert [d.line for d in e.value.diagnostics] == [4, 5]
    with pytest.raises(eamos.CompileError):
        c.run()


def test_a_missing_file_is_a_diagnostic_not_an_exception(tmp_path):
    c = eamos.compile(tmp_path / "nowhere.eamos")
    assert not c.ok
    (d,) = c.diagnostics
    assert d.severity == "error" and d.file is None and d.line == 0
    assert "cannot read mission file" in d.message and "nowhere.eamos" in d.message


def test_fleet_errors_and_mission_errors_come_together():
    fleet = "drones:\n  Drone1: {battery: lots}\n"
    c = eamos.compile_text(BROKEN, name="inline.eamos", fleet_text=fleet)
    files = [(d.file, d.line) for d in c.errors]
    assert ("<fleet>", 2) in files and ("inline.eamos", 4) in files


def test_listing2_graphs_are_what_eamos_graph_writes(eamos_bin):
    c = eamos.compile(LISTING2)
    assert c.ok and c.drones == ["Drone1", "Drone2", "Drone3"]
    assert [d.severity for d in c.diagnostics] == ["warning"] * len(c.warnings)

    def graph(kind, *extra):
        return json.loads(run_eamos(eamos_bin, "graph", LISTING2, "--kind", kind, "--format", "json", *extra).stdout)

    assert c.amt == graph("amt")
    assert c.meg == graph("meg")
    for name in c.drones:
        assert c.mdg(name) == graph("mdg", "--drone", name)
    assert c.mdg(1) == c.mdgs["Drone2"]
    assert c.stats() == json.loads(run_eamos(eamos_bin, "stats", LISTING2).stdout)
    # The MEG names the actions the drones fly; the MDG of Drone2 holds its Orbit.
    assert any(n.get("text") == "Drone2.Orbit()" for n in c.meg["nodes"])
    assert any(n.get("name") == "Orbit" for n in c.mdgs["Drone2"]["nodes"])


def test_mission_file_is_what_eamos_compile_writes(tmp_path, eamos_bin):
    c = eamos.compile(LISTING2)
    run_eamos(eamos_bin, "compile", LISTING2, "-o", tmp_path / "deploy", "--insecure")
    for name in c.drones:
        assert c.mission_file(name) == json.loads((tmp_path / "deploy" / name / "mission.json").read_text())


def test_unknown_drone_names_are_refused_with_the_fleet():
    c = eamos.compile(LISTING2)
    with pytest.raises(KeyError, match="Drone1, Drone2, Drone3"):
        c.mdg("Drone7")
    with pytest.raises(IndexError):
        c.mdg(3)


def test_a_file_of_bytes_that_are_not_text_gives_diagnostics_not_an_exception(tmp_path):
    path = tmp_path / "garbage.eamos"
    path.write_bytes(b"var Drone1 Quad\nfunc INIT() { Drone1.Takeoff(\xff\xfe) }\n\x00\x01garbage\n")
    c = eamos.compile(path)
    assert not c.ok
    assert [(d.line, d.column) for d in c.errors] == [(2, 30), (3, 1)]
    assert "invalid UTF-8: byte 0xff" in c.errors[0].message
    # The source line's bytes that are not UTF-8 are shown escaped, never raw.
    assert "Takeoff(\\xff\\xfe)" in c.errors[0].text
