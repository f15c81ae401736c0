"""Runs from Python: progress, history as numpy arrays, frames, run.json, stop and resume,
sweeps."""

from __future__ import annotations

import csv
import subprocess
import threading

import numpy as np
import pytest

import adhesim
from conftest import INDENTATION_SET, SCENARIOS, adhesim_binary

CANTILEVER = SCENARIOS / "cantilever.toml"


def read_csv_columns(path) -> dict[str, list[float]]:
    """history.csv read with the csv module, independently of adhesim's reader."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header = rows[0]
    return {name: [float(r[k]) for r in rows[1:]] for k, name in enumerate(header)}


def test_run_history_equals_history_csv(out):
    sc = adhesim.Scenario.from_file(CANTILEVER, set={"time.t_end": 0.02})
    steps = []
    run = sc.run(out, progress=steps.append)
    assert run.outcome == "finished"
    summary = run.summary
    assert summary["steps"] == 10 and summary["t_reached"] == pytest.approx(0.02)
    # One call per committed step, in order, with the step's time.
    assert [s.step for s in steps] == list(range(1, 11))
    assert steps[-1].t == pytest.approx(0.02) and steps[-1].t_end == 0.02

    history = run.history()
    expected = read_csv_columns(out / "history.csv")
    assert list(history) == list(expected)
    for name, column in expected.items():
        assert history[name].dtype == np.float64
        # The file holds shortest round-trip decimals: both readers give the same doubles.
        np.testing.assert_array_equal(history[name], np.array(column), err_msg=name)
    # The row at t = 0 and one per step; the callback saw the same times.
    np.testing.assert_array_equal(history["t"][1:], [s.t for s in steps])

    pd = pytest.importorskip("pandas")
    df = run.dataframe()
    assert isinstance(df, pd.DataFrame) and list(df.columns) == list(expected)
    np.testing.assert_array_equal(df["tip.uy"].to_numpy(), history["tip.uy"])


def test_frames_as_numpy_arrays(out):
    sc = adhesim.Scenario.from_file(CANTILEVER, set={"time.t_end": 0.02})
    run = sc.run(out)
    times = run.frame_times()
    assert times[0] == 0.0 and times[-1] == pytest.approx(0.02)
    last = run.frame(-1)
    beam = last.bodies["beam"]
    assert beam.points.shape == (21 * 3 * 3, 3)
    assert len(beam.types) == 80 and set(beam.types) == {12}
    u = beam.point_data["u"]
    assert u.shape == beam.points.shape
    # The tracked tip point is a node: its displacement in the frame is the history's.
    tip = np.argmin(np.linalg.norm(beam.points - u - [0.1, 0.005, 0.005], axis=1))
    history = run.history()
    row = np.argmin(abs(history["t"] - last.t))
    assert u[tip, 1] == pytest.approx(history["tip.uy"][row], rel=1e-12, abs=1e-300)
    assert len(run.frames()) == len(times)


def test_contact_fields_as_numpy_arrays(out):
    sc = adhesim.Scenario.from_file(
        SCENARIOS / "indentation.toml", set={**INDENTATION_SET, "time.t_end": 0.4}
    )
    run = sc.run(out)
    surface = run.frame(-1).contacts["indentor"]
    beta = surface.point_data["beta"]
    assert beta.shape == (len(surface.points),)
    # Bonds form in closed contact (w/b = 200 /s) and β stays in [0, 1].
    assert 0.0 < beta.max() <= 1.0 and beta.min() >= 0.0
    assert surface.point_data["contact_force"].shape == (len(beta), 3)


def indentation(**more):
    return adhesim.Scenario.from_file(
        SCENARIOS / "indentation.toml", set={**INDENTATION_SET, **more}
    )


def same_history(a: dict, b: dict):
    assert list(a) == list(b)
    for name in a:
        if name.startswith("time_"):
            continue  # wall-clock timings of the steps
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)


def stop_at(n):
    return lambda s: s.step < n


def test_stop_request_leaves_a_checkpoint_that_resumes_to_the_same_history(tmp_path):
    reference = indentation().run(tmp_path / "reference", checkpoint_every=0)
    assert reference.outcome == "finished"
    assert reference.summary["steps"] == 50

    stopped_dir = tmp_path / "stopped"
    stopped = indentation().run(stopped_dir, progress=stop_at(20), checkpoint_every=0)
    assert stopped.outcome == "interrupted"
    assert stopped.summary["checkpoint"] == {"step": 20, "t": pytest.approx(0.4)}
    assert (stopped_dir / "checkpoint.bin").exists()
    assert len(stopped.history()["t"]) == 21

    resumed = indentation().run(stopped_dir, resume=True, checkpoint_every=0)
    assert resumed.outcome == "finished"
    assert resumed.summary["resumed_from"]["step"] == 20
    same_history(resumed.history(), reference.history())


def test_stop_request_from_another_thread(tmp_path):
    reference = indentation().run(tmp_path / "reference", checkpoint_every=0)
    stop = adhesim.StopRequest()
    reached = threading.Event()

    def watcher():
        reached.wait(timeout=60)
        stop.set()

    thread = threading.Thread(target=watcher)
    thread.start()
    def signal(step):
        if step.step == 10:
            reached.set()  # returns None: the run goes on

    # The callback only signals; the other thread asks for the stop (while the run computes
    # without the interpreter), so the run ends a step or a few later.
    run_dir = tmp_path / "stopped"
    run = indentation().run(run_dir, stop=stop, checkpoint_every=0, progress=signal)
    thread.join()
    assert stop.is_set()
    assert run.outcome == "interrupted"
    assert 10 <= run.summary["steps"] < 50
    assert (run_dir / "checkpoint.bin").exists()
    resumed = indentation().run(run_dir, resume=True, checkpoint_every=0)
    same_history(resumed.history(), reference.history())


def test_stop_request_resumed_by_the_command_line(tmp_path):
    binary = adhesim_binary()
    if binary is None:
        pytest.skip("the adhesim command is not built (cargo build --release)")
    reference = indentation().run(tmp_path / "reference", checkpoint_every=0)
    stopped_dir = tmp_path / "stopped"
    indentation().run(stopped_dir, progress=stop_at(15), checkpoint_every=0)
    args = [a for kv in INDENTATION_SET.items() for a in ("--set", f"{kv[0]}={kv[1]}")]
    args = [a.replace("[30, 3, 1]", "[30,3,1]") for a in args]
    cli = subprocess.run(
        [binary, "run", SCENARIOS / "indentation.toml", *args, "--resume", stopped_dir, "-q"],
        capture_output=True,
        text=True,
    )
    assert cli.returncode == 0, cli.stderr
    same_history(adhesim.Run(stopped_dir).history(), reference.history())


def test_exception_in_the_callback_stops_the_run_with_a_checkpoint(out):
    def fail(step):
        if step.step == 3:
            raise ValueError("enough")

    with pytest.raises(ValueError, match="enough"):
        adhesim.Scenario.from_file(CANTILEVER).run(out, progress=fail)
    run = adhesim.Run(out)
    assert run.outcome == "interrupted"
    assert (out / "checkpoint.bin").exists()


def test_previous_run_is_refused_unless_overwritten(out):
    sc = adhesim.Scenario.from_file(CANTILEVER, set={"time.t_end": 0.004})
    sc.run(out)
    with pytest.raises(adhesim.RunError, match="overwrite"):
        sc.run(out)
    assert sc.run(out, overwrite=True).outcome == "finished"


def test_sweep_cases_equal_single_runs(tmp_path):
    sc = adhesim.Scenario.from_file(CANTILEVER, set={"time.t_end": 0.02})
    result = sc.sweep(tmp_path / "sweep", {"body.beam.material.g": [1e5, 4e5]}, jobs=2)
    assert len(result.runs) == 2 and not result.interrupted
    assert all(r.outcome == "finished" for r in result.runs)
    table = result.table()
    assert len(next(iter(table.values()))) == 2
    # Each case is the run of the scenario with its value set. The sum order of the
    # parallel assembly depends on the thread count, so the histories agree to round-off,
    # not bit for bit: to 1e-9 of the largest value of the same kind of quantity (the three
    # components of a force, a moment, a displacement or a velocity together, since a
    # component that is zero by symmetry holds only round-off; for the energy balance, a
    # difference of energies, the largest external work). The solver's residuals (round-off
    # themselves) and the wall-clock timings are not compared.
    def kind(name):
        if name == "energy_balance":
            return ["external_work"]
        if name[-1:] in "xyz" and "." in name:
            return [name[:-1] + c for c in "xyz"]
        return [name]

    for g, case in zip([1e5, 4e5], result.runs):
        single = sc.with_options(set={"body.beam.material.g": g}).run(tmp_path / f"g{g}")
        a, b = case.history(), single.history()
        for name in a:
            if name.startswith("time_") or name.endswith("residual"):
                continue
            scale = max(np.abs(b[k]).max() for k in kind(name) if k in b)
            np.testing.assert_allclose(a[name], b[name], rtol=0, atol=1e-9 * scale, err_msg=name)
    assert result.runs[0].history()["tip.uy"][-1] != result.runs[1].history()["tip.uy"][-1]
