"""Scenarios from files and dicts, variants and overrides, and validation errors."""

from __future__ import annotations

import copy
import subprocess

import pytest

import adhesim
from conftest import SCENARIOS, adhesim_binary


def test_dict_round_trip_gives_the_same_problem():
    from_file = adhesim.Scenario.from_file(SCENARIOS / "cantilever.toml")
    doc = from_file.to_dict()
    assert doc["name"] == "cantilever"
    assert doc["body"][0]["mesh"]["divisions"] == [20, 2, 2]
    from_dict = adhesim.Scenario.from_dict(doc, base_dir=SCENARIOS)
    # dict -> TOML -> dict is the identity, and both validate to the same problem (the
    # fingerprint hashes every field of the validated problem).
    assert from_dict.to_dict() == doc
    a, b = from_file.check(), from_dict.check()
    assert a["fingerprint"] == b["fingerprint"]
    assert (a["nodes"], a["cells"]) == (21 * 3 * 3, 20 * 2 * 2)


def test_variant_and_overrides_apply_as_on_the_command_line():
    path = SCENARIOS / "paper" / "indentation.toml"
    base = adhesim.Scenario.from_file(path).check()
    coarse = adhesim.Scenario.from_file(path, variant="coarse").check()
    assert coarse["cells"] < base["cells"]
    changed = adhesim.Scenario.from_file(path, set={"time.dt": 0.05, "time.t_end": 1.0}).check()
    assert (changed["dt"], changed["t_end"]) == (0.05, 1.0)
    # The same override as a KEY=VALUE string.
    same = adhesim.Scenario.from_file(path, set=["time.dt=0.05", "time.t_end=1.0"]).check()
    assert same["fingerprint"] == changed["fingerprint"]


def test_dict_built_in_python():
    doc = {
        "name": "block",
        "time": {"t_end": 0.01, "dt": 1e-3},
        "body": [
            {
                "name": "b",
                "mesh": {"generator": "block", "size": [0.01, 0.01, 0.01], "divisions": [2, 2, 2]},
                "material": {"model": "neo-hookean", "young": 1e6, "poisson": 0.3},
                "density": 1000.0,
            }
        ],
    }
    info = adhesim.Scenario.from_dict(doc).check()
    assert info["name"] == "block" and info["nodes"] == 27


def cantilever_doc() -> dict:
    return adhesim.Scenario.from_file(SCENARIOS / "cantilever.toml").to_dict()


@pytest.mark.parametrize(
    "edit, key",
    [
        # Type errors quote the line of the dict's TOML form, key included.
        (lambda d: d["time"].__setitem__("dt", "fast"), 'dt = "fast"'),
        (lambda d: d["body"][0].__setitem__("densty", 1000.0), "unknown field `densty`"),
        (lambda d: d["body"][0]["material"].__setitem__("g", -1.0), "`body[0].material.g`"),
        (lambda d: d["boundary"][0].__setitem__("set", "nowhere"), "`boundary[0].set`"),
    ],
)
def test_invalid_scenario_raises_scenario_error_naming_the_key(edit, key):
    doc = copy.deepcopy(cantilever_doc())
    edit(doc)
    with pytest.raises(adhesim.ScenarioError) as err:
        adhesim.Scenario.from_dict(doc, base_dir=SCENARIOS).check()
    assert key in str(err.value)
    assert isinstance(err.value, adhesim.AdhesimError)


def test_unknown_override_and_variant_name_the_key():
    path = SCENARIOS / "cantilever.toml"
    with pytest.raises(adhesim.ScenarioError, match="time.dtt"):
        adhesim.Scenario.from_file(path, set={"time.dtt": 1e-3}).check()
    with pytest.raises(adhesim.ScenarioError, match="fine"):
        adhesim.Scenario.from_file(path, variant="fine").check()
    with pytest.raises(adhesim.ScenarioError, match="missing.toml"):
        adhesim.Scenario.from_file(SCENARIOS / "missing.toml")


def test_error_message_is_the_one_of_adhesim_check(tmp_path):
    binary = adhesim_binary()
    if binary is None:
        pytest.skip("the adhesim command is not built (cargo build --release)")
    text = (SCENARIOS / "cantilever.toml").read_text().replace("g = 1e5", "g = -1e5")
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(adhesim.ScenarioError) as err:
        adhesim.Scenario.from_file(path).check()
    cli = subprocess.run([binary, "check", path], capture_output=True, text=True)
    assert cli.returncode == 2
    assert cli.stderr.strip() == f"error: {err.value}"
