"""The figures of the studies that draw the paper's figures as its readers know them (issue 22, item 5): the
node-density table's signed tip deflection (Fig. 9a), the figure drawn from tables with and without it."""
from __future__ import annotations

import json
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


def _collapse_run(folder: Path, times: tuple[float, ...]) -> pd.DataFrame:
    """A run folder of the column collapse with a sliding block saved at ``times`` (a pvd of vtu states with the
    tracked boundary and the displacement), and its one-row table."""
    import meshio

    from ctmrpim.io.vtu import pvd_text

    gx, gy = np.meshgrid(np.linspace(0, 0.2, 9), np.linspace(0, 0.1, 5))
    x0 = np.c_[gx.ravel(), gy.ravel(), np.zeros(gx.size)]
    ring = [0, 8, 44, 36]
    edges = np.array([(a, b) for a, b in zip(ring, ring[1:] + ring[:1])])
    entries = []
    for k, t in enumerate(times):
        u = np.c_[t * x0[:, 1] * x0[:, 0], -0.1 * t * x0[:, 0] * x0[:, 1], np.zeros(gx.size)]
        name = f"step_{k:05d}.vtu"
        meshio.write(folder / name, meshio.Mesh(x0 + u, [("line", edges)],
                                                point_data={"u": u, "displacement": np.hypot(u[:, 0], u[:, 1])}))
        entries.append((t, name))
    (folder / "result.pvd").write_text(pvd_text(entries))
    xs = np.linspace(0, 0.3, 7)
    return pd.DataFrame([{"grid": "9 x 5", "status": "ok", "folder": str(folder), "nodes": 45, "at_rest": False,
                          "end_time_s": times[-1], "run_out_m": 0.25, "height_at_wall_m": 0.1,
                          "run_out_measured_m": 0.36, "failure": "[[0.0, 0.05], [0.1, 0.0]]",
                          "profile": json.dumps({"x": xs.tolist(), "h": np.clip(0.1 - xs / 3, 0, None).tolist()})}])


@pytest.mark.parametrize(("times", "last"), [((0.0, 0.1, 0.2, 0.3, 0.62), "(e) 9 x 5: t = 0.62 s, final configuration"),
                                             ((0.0, 0.05, 0.1), "(b) 9 x 5: t = 0.10 s, mid-flow")])
def test_the_collapse_figure_starts_with_the_initial_configuration(tmp_path: Path, times, last: str) -> None:
    """Fig. 27: panel (a) is the initial configuration, then the snapshots, the last one called final only where
    the run reached a deposit (a quick run's 0.1 s is mid-flow, not final)."""
    from studies import column_collapse

    fig = column_collapse.figure(_collapse_run(tmp_path, times))
    titles = [ax.get_title() for ax in fig.get_axes() if ax.get_title().startswith("(")]
    assert titles[0].startswith("(a) 9 x 5: t = 0.00 s, initial configuration")
    assert titles[-1].startswith(last) and len(titles) == (5 if times[-1] > 0.6 else 2)
    assert all("final" not in t or "not final" in t for t in titles[:-1])
    fig.savefig(tmp_path / "collapse.png")


def test_the_cantilever_loads_fall_on_increments() -> None:
    """The tip loads drawn (Fig. 15: 2000 and 3000 kN in full mode) are reached at increments' ends, with no more
    increments than the tip-load study's rule gives (quick: 6 for 1500 kN, not 8)."""
    from ctmrpim.reference import elastica
    from studies import deformed_shapes

    assert elastica.paper_lambda(3000.0) == pytest.approx(3.6) and elastica.paper_lambda(2000.0) == pytest.approx(2.4)
    assert deformed_shapes.load_steps(deformed_shapes.FULL_LOADS_KN) == 15
    assert deformed_shapes.load_steps(deformed_shapes.QUICK_LOADS_KN) == 6
    assert deformed_shapes.load_steps((100.0, 3000.0)) == 30


def test_the_footing_case_is_a_relaxation_at_540_kpa() -> None:
    """Fig. 25's footing: the benchmark as a dynamic-relaxation run, the paper's 540 kPa applied at once, the steps
    stated."""
    from studies import stability_fields

    case = stability_fields.footing_case(540.0, 123)
    assert case.problem.analysis == "dynamic" and case.relaxation.steps == 123
    assert case.resolved["parameters"]["q_max"] == pytest.approx(540e3) and "loading" not in case.resolved


def test_the_full_figures_section_lists_committed_figures_with_their_state(tmp_path: Path) -> None:
    """The quick report's list of committed full-mode figures: each committed one with its provenance state (an
    unstamped one flagged), none where nothing is committed."""
    from studies.report import full_figures

    text: list[str] = []
    full_figures.write_full_figures(text.append, tmp_path)
    assert "No full-mode figure is committed" in "".join(text)
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "slope_relaxation.png").write_bytes(b"\x89PNG\r\n\x1a\n")
    text.clear()
    full_figures.write_full_figures(text.append, tmp_path)
    out = "".join(text)
    assert "![slope relaxation, full mode](full/slope_relaxation.png)" in out and "**unstamped**" in out
    assert "Fig. 19a" in out and "node_density" not in out
