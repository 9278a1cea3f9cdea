"""The module installed by `cmake --install` (component python) imports and works from there."""

import os
import subprocess
import sys

from conftest import LISTING2


def test_installed_module_compiles_and_runs_a_mission(tmp_path, build_dir):
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", str(build_dir), "--component", "python", "--prefix", str(prefix)],
                   check=True, capture_output=True, timeout=120)
    site = prefix / os.environ["EAMOS_PYTHON_PACKAGE_DIR"]
    assert (site / "eamos" / "__init__.py").is_file()
    code = (
        "import eamos\n"
        "print(eamos.__file__)\n"
        f"r = eamos.run({str(LISTING2)!r})\n"
        "print(r.completed, r.duration)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(site)}
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path, timeout=60)
    assert p.returncode == 0, p.stderr
    where, outcome = p.stdout.splitlines()
    assert where == str(site / "eamos" / "__init__.py")
    assert outcome.startswith("True ")
