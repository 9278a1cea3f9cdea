"""What the tests of the Python module share: where the repository, the eamos command and the
build tree are (tests/python/CMakeLists.txt passes them from CMake), and running eamos."""

import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
LISTING2 = ROOT / "examples" / "listing2.eamos"


def _env_path(name):
    value = os.environ.get(name)
    if not value:
        pytest.fail(f"{name} is not set: run these tests through ctest (tests/python/CMakeLists.txt sets it)")
    return pathlib.Path(value)


@pytest.fixture(scope="session")
def eamos_bin():
    return _env_path("EAMOS_BIN")


@pytest.fixture(scope="session")
def build_dir():
    return _env_path("EAMOS_BUILD_DIR")


def run_eamos(eamos_bin, *args, expect=0):
    """Runs `eamos ARGS` from the repository root; returns the completed process."""
    p = subprocess.run([str(eamos_bin), *map(str, args)], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert p.returncode == expect, f"eamos {' '.join(map(str, args))} exited {p.returncode}:\n{p.stdout}\n{p.stderr}"
    return p


@pytest.fixture(scope="session")
def cli_listing2(eamos_bin, tmp_path_factory):
    """Listing 2 flown by `eamos run` with a trace and a summary: the reference for the module."""
    out = tmp_path_factory.mktemp("cli")
    trace, summary = out / "trace.jsonl", out / "summary.json"
    run_eamos(eamos_bin, "run", "-q", LISTING2, "--trace", trace, "--summary", summary)
    return {"trace": trace, "summary": json.loads(summary.read_text())}


def pytest_configure(config):
    config.addinivalue_line("markers", "realtime: flies on the wall clock (ctest runs these under the label realtime)")
