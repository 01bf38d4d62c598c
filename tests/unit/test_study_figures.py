"""The figures of the studies that draw the paper's figures as its readers know them (issue 22, item 5): the
node-density table's signed tip deflection (Fig. 9a), the figure drawn from tables with and without it."""
from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
import pytest

from studies import node_density

matplotlib.use("Agg")

ROOT = Path(__file__).resolve().parents[2]


def _summary(uy: float) -> dict:
    """A cantilever summary with the benchmark's parameters and exact field, the tip at (L, 0) deflected by uy."""
    import tomllib

    from ctmrpim import benchmarks
    raw = tomllib.loads(benchmarks.path("cantilever").read_text())
    p = {**raw["parameters"], "I": raw["parameters"]["W"] ** 3 / 12}
    return {"parameters": {"parameters": p, "exact": raw["exact"]},
            "probes": {"tip": {"x": p["L"], "y": 0.0, "ux": 0.0, "uy": uy}}}


def test_the_exact_tip_deflection_is_timoshenkos() -> None:
    """The exact tip deflection is P L^3 / (3 E I) plus the shear term of Eq. (35) at (L, 0): -0.0089 m for the
    paper's beam (Table 1), and the ratio carries the sign the error drops."""
    out = node_density.extra(_summary(-0.009))
    P, E, nu, L, W = -1000.0, 3.0e7, 0.3, 48.0, 12.0
    I = W ** 3 / 12
    assert out["tip_uy_exact"] == pytest.approx(P * L ** 3 / (3 * E * I) + P * (4 + 5 * nu) * W ** 2 * L / (24 * E * I))
    assert out["tip_uy_exact"] == pytest.approx(-0.0089)
    assert out["tip_ratio"] == pytest.approx(0.009 / 0.0089) and out["tip_uy"] == -0.009


def _table(deflection: bool) -> pd.DataFrame:
    rows = []
    for method, err in (("ctm-rpim", 1e-2), ("fem-q1", 3e-2)):
        for k, nodes in enumerate((85, 297, 1105)):
            e = err / 4 ** k
            rows.append({"method": method, "status": "ok", "nodes": nodes, "h": 3.0 / 2 ** k, "tip_error": e,
                         "energy_error": 2 * e, **({"tip_uy": -0.0089 * (1 - e), "tip_uy_exact": -0.0089,
                                                    "tip_ratio": 1 - e} if deflection else {})})
    return pd.DataFrame(rows)


@pytest.mark.parametrize("deflection", [True, False])
def test_the_figure_draws_fig_9a_where_the_table_has_the_deflection(deflection: bool) -> None:
    """Three panels (deflection, tip error, energy error) from a table with the tip deflection, two from an older
    table without it; every axis labelled with its quantity and unit."""
    fig = node_density.figure(_table(deflection))
    axes = fig.get_axes()
    assert len(axes) == (3 if deflection else 2)
    for ax in axes:
        assert "(" in ax.get_xlabel() and ax.get_ylabel().endswith(")")
    if deflection:
        assert "Fig. 9a" in axes[0].get_title()
        assert np.allclose(axes[0].get_lines()[0].get_ydata(), 1 - np.array([1e-2, 2.5e-3, 6.25e-4]))


def test_the_committed_full_table_has_the_deflection() -> None:
    """The committed full-mode table carries the signed deflection, and its error is the ratio's distance from 1."""
    path = ROOT / "reports" / "full" / "node_density.csv"
    if not path.is_file():
        pytest.skip("no committed full-mode table")
    df = pd.read_csv(path, usecols=["status", "tip_error", "tip_uy", "tip_uy_exact", "tip_ratio"])
    ok = df[df.status == "ok"]
    assert np.allclose(ok.tip_error, (ok.tip_ratio - 1).abs(), rtol=1e-9, atol=1e-15)
    assert np.allclose(ok.tip_uy / ok.tip_uy_exact, ok.tip_ratio)
    assert np.allclose(ok.tip_uy_exact, -0.0089)
