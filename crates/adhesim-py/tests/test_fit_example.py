"""examples/fit_pull_off.py recovers the interface parameters it generated its curve with."""

from __future__ import annotations

import importlib.util

from conftest import REPO


def load_example():
    path = REPO / "examples" / "fit_pull_off.py"
    spec = importlib.util.spec_from_file_location("fit_pull_off", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_fit_recovers_cn_and_w(tmp_path):
    example = load_example()
    u, f = example.measured_curve(noise=0.01, seed=1, out=tmp_path / "measured")
    result = example.fit(u, f, work=tmp_path)
    # With 1 % noise on 101 points the standard errors are about 0.3 % for both values. A
    # fit within 4 standard errors of the truth (and within 2 %) is a recovery; a wrong
    # model, a wrong sign or a stuck optimiser from the start (×1/3, ×1/2.5) is far outside.
    for key in ("cn", "w"):
        error = abs(result[key] / example.TRUE[key] - 1)
        se = result[f"{key}_rel_se"]
        assert 0 < se < 0.01, (key, se)
        assert error < 4 * se and error < 0.02, (key, result[key], error, se)
