"""The README's Python example runs as printed, from a folder laid out like the repository's
root, so that the README cannot drift from the module."""

from __future__ import annotations

import subprocess
import sys

import readme_blocks
from conftest import SCENARIOS


def test_readme_python_example_runs_as_printed(tmp_path):
    code = readme_blocks.python_example(readme_blocks.README.read_text(encoding="utf-8"))
    (tmp_path / "scenarios").symlink_to(SCENARIOS, target_is_directory=True)
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    # print(sc.check()["warnings"]), the cantilever's outcome and tip deflection, then the
    # coarse indentation's frame time and largest β.
    assert lines[0] == "[]", lines
    outcome, t_end, tip_uy = lines[1].rsplit(" ", 2)
    assert "finished" in outcome and float(t_end) == 0.1 and float(tip_uy) < 0, lines
    # At t = 2 s the cylinder has been pressed in and held: the bonds at the centre have
    # grown to saturation (β = 1 after 1/(w/b) = 5 ms in contact, docs/model.md).
    t, beta_max = map(float, lines[2].split())
    assert abs(t - 2.0) < 1e-9 and abs(beta_max - 1.0) < 1e-9, lines
    assert (tmp_path / "out" / "cantilever" / "history.csv").is_file()
