"""Fit the adhesive interface of a pad to a pull-off curve with scipy.optimize.

The pad of scenarios/pad-pull-off.toml is pulled off a rigid adhesive flat; the force on
the flat against its displacement depends on the interface's normal stiffness C_n (the
slope before the peak, in series with the pad) and its adhesion energy w (the peak is near
√(C_n w) per unit area, the tail falls as w²/(C_n u³)). This script makes a "measured"
curve by running the model at known values (C_n = 1e10 N/m³, w = 0.05 J/m²) and adding
Gaussian noise of 1 % of the pull-off force (the peak tensile force), then fits log10 C_n and log10 w to it by least
squares from a start a factor 3 and 2.5 away, one adhesim run per evaluation.

    pip install crates/adhesim-py scipy
    python examples/fit_pull_off.py            # about 10 s

To fit a curve of your own, replace `measured` by your displacement [m] and force [N]
arrays (displacement of the flat, positive towards the pad; force on the flat, positive
when it pushes the flat away) and adapt the scenario's geometry, material and motion.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

import adhesim

SCENARIO = Path(__file__).resolve().parent.parent / "scenarios" / "pad-pull-off.toml"
TRUE = {"cn": 1e10, "w": 0.05}
T_PULL = 0.2  # the pull starts after the hold [s]


def pull_off_curve(cn: float, w: float, out: Path) -> tuple[np.ndarray, np.ndarray]:
    """The model's curve during the pull: the flat's displacement [m] and the force the pad
    exerts on it [N] (the reaction on the rigid master, y component)."""
    scenario = adhesim.Scenario.from_file(SCENARIO, set={"cn": cn, "w": w})
    run = scenario.run(out, overwrite=True, checkpoint_every=0)
    if run.outcome != "finished":
        raise RuntimeError(f"run at cn={cn:g}, w={w:g}: {run.messages}")
    h = run.history()
    pulling = h["t"] >= T_PULL
    return h["flat.master.uy"][pulling], h["flat.master.Fy"][pulling]


def measured_curve(noise: float, seed: int, out: Path) -> tuple[np.ndarray, np.ndarray]:
    """The synthetic experiment: the model at TRUE plus noise of `noise` times the peak."""
    u, f = pull_off_curve(TRUE["cn"], TRUE["w"], out)
    rng = np.random.default_rng(seed)
    return u, f + noise * f.max() * rng.standard_normal(f.shape)


def fit(
    u_measured: np.ndarray,
    f_measured: np.ndarray,
    start: tuple[float, float] = (3e9, 0.02),
    work: Path | None = None,
) -> dict:
    """Least-squares fit of (C_n, w) to a measured curve (displacements within the
    model's pull, decreasing). Returns the fitted values, their standard errors (from the Jacobian at
    the optimum and the residual variance) and the number of model runs."""
    work = Path(work or tempfile.mkdtemp(prefix="adhesim-fit-"))
    runs = 0

    def residual(x: np.ndarray) -> np.ndarray:
        nonlocal runs
        runs += 1
        u, f = pull_off_curve(10 ** x[0], 10 ** x[1], work / "model")
        # The model's steps need not fall on the measured displacements (a step that cuts
        # Δt back adds points): interpolate it there. The flat goes down (u decreasing).
        f_model = np.interp(-u_measured, -u, f)
        return (f_model - f_measured) / f_measured.max()

    x0 = np.log10(start)
    # Finite-difference steps of 0.1 % of log10 of the values: small against the fit's
    # scale, large against the model's own round-off (its Newton tolerances).
    result = least_squares(residual, x0, x_scale=1.0, diff_step=1e-3)
    # Standard errors of log10 C_n and log10 w: s² (JᵀJ)⁻¹ with s² the residual variance
    # and J by central differences of ±0.002 in log10 (±0.5 % in the values).
    h = 0.002
    jac = np.column_stack(
        [
            (residual(result.x + h * e) - residual(result.x - h * e)) / (2 * h)
            for e in np.eye(2)
        ]
    )
    dof = len(result.fun) - len(result.x)
    s2 = float(result.fun @ result.fun) / dof
    cov = s2 * np.linalg.inv(jac.T @ jac)
    se_log = np.sqrt(np.diag(cov))
    cn, w = 10 ** result.x
    return {
        "cn": cn,
        "w": w,
        # Relative standard error of the value: d(10^x)/10^x = ln(10) dx.
        "cn_rel_se": np.log(10) * se_log[0],
        "w_rel_se": np.log(10) * se_log[1],
        "runs": runs,
        "cost": result.cost,
    }


def main() -> None:
    with tempfile.TemporaryDirectory(prefix="adhesim-fit-") as tmp:
        u, f = measured_curve(noise=0.01, seed=1, out=Path(tmp) / "measured")
        print(f"measured: {len(u)} points, pull-off force {f.max():.4g} N")
        r = fit(u, f, work=Path(tmp))
    for key, unit in [("cn", "N/m³"), ("w", "J/m²")]:
        err = r[key] / TRUE[key] - 1
        print(
            f"{key:>2} = {r[key]:.5g} {unit} (true {TRUE[key]:g}; error {100 * err:+.2f} %, "
            f"standard error {100 * r[key + '_rel_se']:.2f} %)"
        )
    print(f"{r['runs']} model runs")


if __name__ == "__main__":
    main()
