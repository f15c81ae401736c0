"""Shared fixtures: the repository's paths and the small scenarios the tests run."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
SCENARIOS = REPO / "scenarios"

# The coarse indentation of tests/restart.rs (crates/adhesim): 30 × 3 × 1 hexahedra, the
# loading phase only (1 s, 50 steps), contact and bonds forming from the first steps, so a
# resumed run must carry β, the contact state and the frames across the checkpoint.
INDENTATION_SET = {
    "time.t_end": 1.0,
    "body.layer.mesh.divisions": [30, 3, 1],
}


@pytest.fixture
def out(tmp_path: Path) -> Path:
    return tmp_path / "out"


def adhesim_binary() -> Path | None:
    """The `adhesim` command: $ADHESIM_BIN, else the release build of this repository."""
    env = os.environ.get("ADHESIM_BIN")
    if env:
        return Path(env)
    built = REPO / "target" / "release" / "adhesim"
    if built.exists():
        return built
    found = shutil.which("adhesim")
    return Path(found) if found else None
