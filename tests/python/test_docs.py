"""docs/python.md's notebook runs as written: each ```python cell in order, in one namespace,
printing what the ```text block after it shows, and drawing a picture with something in it."""

import json
import os
import re
import subprocess
import sys

import pytest

from conftest import ROOT

DOC = ROOT / "docs" / "python.md"

# Runs the cells given as JSON on standard input in one namespace; prints, as JSON, what each
# printed.
DRIVER = """
import contextlib, io, json, sys
cells = json.load(sys.stdin)
namespace = {"__name__": "__main__"}
outputs = []
for cell in cells:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(cell, "<docs/python.md>", "exec"), namespace)
    outputs.append(out.getvalue())
print(json.dumps(outputs))
"""


def cells(text):
    """Each python cell with the text block that follows it (None when none does)."""
    blocks = re.findall(r"^```(\w+)\n(.*?)^```$", text, re.M | re.S)
    out = []
    for i, (lang, body) in enumerate(blocks):
        if lang == "python":
            after = blocks[i + 1] if i + 1 < len(blocks) else None
            out.append((body, after[1] if after and after[0] == "text" else None))
    return out


def test_the_notebook_in_docs_python_md_runs_and_prints_what_it_shows(tmp_path):
    notebook = cells(DOC.read_text())
    assert len(notebook) >= 5
    # The cells name examples/listing2.eamos from the repository's root; they run in a
    # scratch folder that has it, so that what they write lands there.
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    env = {**os.environ, "MPLBACKEND": "Agg"}
    p = subprocess.run([sys.executable, "-c", DRIVER], input=json.dumps([c for c, _ in notebook]), cwd=tmp_path,
                       env=env, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    printed = json.loads(p.stdout)
    for (cell, shown), out in zip(notebook, printed):
        if shown is not None:
            assert out == shown, f"the cell\n{cell}\nprints\n{out}\nbut docs/python.md shows\n{shown}"
    assert (tmp_path / "listing2.jsonl").is_file()
    check_picture(tmp_path / "listing2-run.png")


def check_picture(path):
    """Two panels with a coloured line per drone: not blank, not one colour."""
    import matplotlib.image
    import numpy

    image = matplotlib.image.imread(str(path))
    height, width = image.shape[:2]
    assert (width, height) == (1100, 450)
    rgb = (image[:, :, :3] * 255).astype(int)
    # matplotlib's first three colours (blue, orange, green): one line per drone.
    for colour in [(31, 119, 180), (255, 127, 14), (44, 160, 44)]:
        matches = numpy.all(numpy.abs(rgb - colour) <= 8, axis=2)
        assert matches.sum() > 200, f"hardly any pixels of colour {colour}: a drone's line is missing"
        # On both panels: left half (tracks) and right half (altitude).
        assert matches[:, : width // 2].sum() > 50 and matches[:, width // 2 :].sum() > 50


def test_the_python_lines_in_the_readme_run(tmp_path):
    (code,) = [body for lang, body in re.findall(r"^```(\w+)\n(.*?)^```$", (ROOT / "README.md").read_text(), re.M | re.S)
               if lang == "python"]
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    code += "print(result.completed, len(df) == len(eamos.load_trace('run.jsonl').of('telemetry')))\n"
    p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert p.stdout.splitlines()[-1] == "True True"
    assert "mission" in p.stdout  # the callback printed the mission's end
