"""adhesim from Python: load, validate and run scenarios, read their results as numpy arrays.

    import adhesim
    sc = adhesim.Scenario.from_file("scenarios/cantilever.toml", set={"time.t_end": 0.05})
    run = sc.run("out/cantilever", overwrite=True, progress=lambda s: print(s.step, s.t))
    h = run.history()            # dict: column name -> numpy array
    print(h["t"][-1], h["tip.uy"][-1], run.summary["outcome"])

A scenario is the TOML document of docs/scenario.md, from a file or as a dict with the same
structure; `variant` and `set` are `--variant` and `--set` of the command line. Validation
gives the messages of `adhesim check`, raised as `ScenarioError`. See docs/python.md.
"""

from __future__ import annotations

import json
import numbers
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping

import numpy as np

from . import _native
from ._native import AdhesimError, RunError, ScenarioError, StopRequest
from .frames import Frame, read_frame, read_frames, frame_times

__version__ = _native.__version__

__all__ = [
    "AdhesimError",
    "Frame",
    "Run",
    "RunError",
    "Scenario",
    "ScenarioError",
    "Step",
    "StopRequest",
    "SweepResult",
    "read_history",
    "sweep",
]


def _override_text(key: str, value: Any) -> str:
    """One `KEY=VALUE` override, the value written as TOML (as on the command line)."""
    if isinstance(value, str):
        # A bare word is read as a string; quoting keeps any text a string.
        return f"{key}={json.dumps(value)}"
    if isinstance(value, (bool, np.bool_)):
        return f"{key}={'true' if value else 'false'}"
    if isinstance(value, numbers.Integral):
        return f"{key}={int(value)}"
    if isinstance(value, numbers.Real):
        return f"{key}={float(value)!r}"
    if isinstance(value, (list, tuple, np.ndarray)):
        return f"{key}={_toml_inline(value)}"
    raise ScenarioError(
        f"override `{key}`: cannot write {value!r} as a TOML value "
        "(numbers, strings, booleans or lists of them)"
    )


def _toml_inline(value: Any) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return repr(float(value))
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_toml_inline(v) for v in value) + "]"
    raise ScenarioError(f"cannot write {value!r} as a TOML value")


def _overrides(set: Mapping[str, Any] | Iterable[str] | None) -> list[str]:
    if set is None:
        return []
    if isinstance(set, Mapping):
        return [_override_text(k, v) for k, v in set.items()]
    return [str(s) for s in set]


@dataclass(frozen=True)
class Step:
    """A committed step, as passed to a run's progress callback."""

    step: int
    """Step number (1-based)."""
    t: float
    """Time at the end of the step [s]."""
    t_end: float
    """End time of the run [s]."""
    dt: float
    """Step size used [s]."""
    newton_iterations: int
    cutbacks: int
    residual: float
    kinetic: float
    """Kinetic energy [J]."""
    internal: float
    """Strain energy [J]."""
    external_work: float
    """Work of loads, gravity, supports and contact since t = 0 [J]."""
    contact_points: int


class Scenario:
    """A scenario: its TOML text, the path that names it (and anchors relative mesh files),
    a variant and overrides. Nothing is validated until `check()` or `run()`."""

    def __init__(
        self,
        text: str,
        path: str | os.PathLike,
        *,
        variant: str | None = None,
        set: Mapping[str, Any] | Iterable[str] | None = None,
        from_file: bool = True,
    ):
        self.text = text
        self.path = Path(path)
        self.variant = variant
        self.overrides = _overrides(set)
        self._from_file = from_file

    @classmethod
    def from_file(
        cls,
        path: str | os.PathLike,
        *,
        variant: str | None = None,
        set: Mapping[str, Any] | Iterable[str] | None = None,
    ) -> "Scenario":
        """Reads a scenario file. `set` maps dotted keys (or parameter names) to values,
        or lists `KEY=VALUE` strings, as `--set` does."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as e:
            raise ScenarioError(f"{path}: cannot read the scenario file: {e}") from None
        return cls(text, path, variant=variant, set=set)

    @classmethod
    def from_dict(
        cls,
        doc: Mapping[str, Any],
        *,
        base_dir: str | os.PathLike = ".",
        variant: str | None = None,
        set: Mapping[str, Any] | Iterable[str] | None = None,
    ) -> "Scenario":
        """A scenario from a dict shaped like the TOML document (`[[body]]` is a list of
        dicts under "body", and so on). Relative mesh files are found from `base_dir`;
        messages name the scenario `<base_dir>/<name>.toml`."""
        text = _native.json_to_toml(json.dumps(doc))
        name = doc.get("name", "scenario") if isinstance(doc, Mapping) else "scenario"
        path = Path(base_dir) / f"{name}.toml"
        return cls(text, path, variant=variant, set=set, from_file=False)

    def with_options(
        self,
        *,
        variant: str | None = None,
        set: Mapping[str, Any] | Iterable[str] | None = None,
    ) -> "Scenario":
        """The same document with another variant and more overrides (after these ones)."""
        s = Scenario(
            self.text, self.path, variant=variant or self.variant, from_file=self._from_file
        )
        s.overrides = self.overrides + _overrides(set)
        return s

    def to_dict(self) -> dict:
        """The document as written (variant and overrides not applied): a dict that
        `Scenario.from_dict` turns back into the same scenario."""
        return json.loads(_native.toml_to_json(self.text, os.fspath(self.path)))

    def check(self) -> dict:
        """Validates the scenario as `adhesim check` does. Returns its name, bodies, node
        and cell counts, t_end, dt, a fingerprint of the validated problem and the physical
        warnings; raises `ScenarioError` naming the file, the key and what is valid."""
        return json.loads(
            _native.check(self.text, os.fspath(self.path), self.variant, self.overrides)
        )

    def run(
        self,
        out: str | os.PathLike,
        *,
        progress: Callable[[Step], Any] | None = None,
        checkpoint_every: int = 100,
        resume: bool = False,
        overwrite: bool = False,
        stop_after_steps: int | None = None,
        stop: StopRequest | None = None,
    ) -> "Run":
        """Runs the scenario into the folder `out`, as `adhesim run` does.

        `progress(step)` is called after every committed step with a `Step`; returning
        False (not None) stops the run after that step with a checkpoint, as Ctrl-C does
        for the command line (Ctrl-C here does the same, then raises KeyboardInterrupt).
        `stop`, a `StopRequest`, does the same when another thread calls `stop.set()`:
        the run releases the interpreter while it computes.
        `resume=True` continues an interrupted run in `out` from its checkpoint;
        `overwrite=True` replaces a previous run there. Raises `ScenarioError` for an
        invalid scenario and `RunError` when the run cannot start or write its outputs; a
        run that stops early (Δt below its minimum) returns normally with
        `run.outcome == "failed"`."""
        callback = None
        if progress is not None:

            def callback(d: dict) -> Any:
                return progress(Step(**d))

        summary, messages = _native.run(
            self.text,
            os.fspath(self.path),
            os.fspath(out),
            variant=self.variant,
            overrides=self.overrides,
            callback=callback,
            checkpoint_every=checkpoint_every,
            resume=resume,
            overwrite=overwrite,
            stop_after_steps=stop_after_steps,
            from_file=self._from_file,
            stop=stop,
        )
        return Run(out, messages=messages)

    def sweep(self, out: str | os.PathLike, axes: Mapping[str, Iterable[Any]], **kwargs):
        """A parameter study of this scenario: see `adhesim.sweep`. A scenario that came
        from a dict is first written to `out/<name>.toml`."""
        path = self.path
        if not self._from_file:
            Path(out).mkdir(parents=True, exist_ok=True)
            path = Path(out) / self.path.name
            path.write_text(self.text, encoding="utf-8")
        return sweep(
            path, out, axes, variant=self.variant, fix=self.overrides, **kwargs
        )


def read_history(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """A history.csv as a dict of column name -> 1-D float64 array (in file order)."""
    names, rows, data = _native.read_history(os.fspath(path))
    table = np.frombuffer(data, dtype="<f8").reshape(rows, len(names))
    return {name: table[:, k].copy() for k, name in enumerate(names)}


class Run:
    """The outputs of a run in a folder (finished, interrupted or failed)."""

    def __init__(self, out: str | os.PathLike, *, messages: list[str] | None = None):
        self.dir = Path(out)
        self.messages = list(messages or [])
        """Messages of the run: the reason it stopped early, figures not drawn."""

    @property
    def summary(self) -> dict:
        """run.json as a dict (read each time: it changes while a run goes on)."""
        with open(self.dir / "run.json", encoding="utf-8") as f:
            return json.load(f)

    @property
    def outcome(self) -> str:
        """"finished", "interrupted", "failed" or "running"."""
        return self.summary["outcome"]["status"]

    def history(self) -> dict[str, np.ndarray]:
        """history.csv as a dict of column name -> numpy array."""
        return read_history(self.dir / "history.csv")

    def dataframe(self):
        """history.csv as a pandas DataFrame (needs pandas)."""
        try:
            import pandas as pd
        except ImportError:  # pragma: no cover - depends on the machine
            raise ImportError(
                "Run.dataframe() needs pandas (pip install pandas); "
                "Run.history() gives the same columns as numpy arrays"
            ) from None
        return pd.DataFrame(self.history())

    def frame_times(self) -> np.ndarray:
        """The times of the frames written [s]."""
        return frame_times(self.dir)

    def frame(self, index: int) -> Frame:
        """Frame `index` (negative counts from the end): each body's and each contact
        surface's points, cells and fields as numpy arrays."""
        return read_frame(self.dir, index)

    def frames(self) -> list[Frame]:
        """Every frame written, in time order."""
        return read_frames(self.dir)

    def __repr__(self) -> str:
        return f"Run({str(self.dir)!r})"


@dataclass
class SweepResult:
    """What a sweep did: each case's label, folder and run (None when it could not run)."""

    dir: Path
    labels: list[str]
    runs: list[Run | None]
    errors: list[str | None]
    interrupted: bool

    def table(self) -> dict[str, np.ndarray]:
        """sweep.csv (one row per case) with its numeric columns as arrays and the others
        as lists of strings."""
        import csv

        with open(self.dir / "sweep.csv", newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
        header, body = rows[0], rows[1:]
        out: dict[str, Any] = {}
        for k, name in enumerate(header):
            col = [r[k] for r in body]
            try:
                out[name] = np.array([float(v) for v in col])
            except ValueError:
                out[name] = col
        return out


def sweep(
    scenario: str | os.PathLike,
    out: str | os.PathLike,
    axes: Mapping[str, Iterable[Any]],
    *,
    variant: str | None = None,
    fix: Mapping[str, Any] | Iterable[str] | None = None,
    jobs: int = 1,
    checkpoint_every: int = 100,
    resume: bool = False,
    overwrite: bool = False,
) -> SweepResult:
    """Runs a parameter study as `adhesim sweep` does: the cartesian product of `axes`
    (key -> values) on the scenario file, `jobs` cases at a time, each in a sub-folder of
    `out`, then sweep.csv and the comparison figures. `fix` holds overrides common to
    every case."""
    axis_texts = [
        f"{key}=" + ",".join(_override_text(key, v).split("=", 1)[1] for v in values)
        for key, values in axes.items()
    ]
    result = json.loads(
        _native.sweep(
            os.fspath(scenario),
            os.fspath(out),
            axis_texts,
            variant=variant,
            fixed=_overrides(fix),
            jobs=jobs,
            checkpoint_every=checkpoint_every,
            resume=resume,
            overwrite=overwrite,
        )
    )
    out = Path(out)
    return SweepResult(
        dir=out,
        labels=[c["label"] for c in result["cases"]],
        runs=[Run(out / c["dir"]) if c["run"] is not None else None for c in result["cases"]],
        errors=[c["error"] for c in result["cases"]],
        interrupted=result["interrupted"],
    )
