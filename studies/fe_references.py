"""Three codes on the same problems (not in the paper): CTM-RPIM, scikit-fem and FEniCSx (dolfinx), which
shares no code with the other two. Every golden case of ``reference_fem/fenicsx_golden.py`` (each linear
benchmark, a user's problem file with a hole, pressure and gravity, and the neo-Hookean tip load) is solved
here by CTM-RPIM on the same nodes and by scikit-fem on the same mesh and element as the committed FEniCSx
result, which is read, not recomputed (dolfinx is optional; ``python -m reference_fem.fenicsx_golden --check``
re-solves it). The table sets the three side by side: errors against the exact solution where there is one,
the tip probe, and how far scikit-fem is from FEniCSx (strain energy and tip, relative). The converged FEniCSx
values (P2 and P3 on refined meshes, Richardson extrapolation) stand in for an exact solution where none exists:
the fully clamped cantilever and the tip-loaded continuum beam; CTM-RPIM is measured against them.
"""
from __future__ import annotations

import json
import sys
from functools import cache
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from reference_fem.fenicsx_golden import CASES, FOLDER, read
from studies.sweep import CaseSpec

from .base import finished, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "fe_references"
TITLE = "CTM-RPIM, scikit-fem and FEniCSx on the same problems"
#: the converged FEniCSx values (python -m reference_fem.fenicsx_converged)
CONVERGED = FOLDER / "converged.json"
#: converged series -> (target, the probe component compared)
CONVERGED_CASES = {"cantilever-clamped": ("cantilever-clamped.toml", "uy"), "tip-load": ("tip-load", "uy")}


def _target(target: str) -> str:
    """A golden case's target as the sweep takes it: a benchmark name, or the path of a file beside the goldens."""
    return str(FOLDER / target) if target.endswith(".toml") else target


def specs(quick: bool) -> list[CaseSpec]:
    """scikit-fem on every golden case, CTM-RPIM once per distinct problem (its default scheme), and CTM-RPIM on
    the problems of the converged values. The same cases in both modes (the golden cases are fixed)."""
    fem = [CaseSpec(_target(g.target), g.overrides, "fem", g.element, labels=(("case", g.name),
                                                                              ("element", g.element)))
           for g in CASES]
    problems = {(g.target, g.overrides): g.name.rsplit("-", 1)[0] for g in CASES}
    problems |= {(target, ()): name for name, (target, _) in CONVERGED_CASES.items()}
    ours = [CaseSpec(_target(target), overrides, labels=(("case", name), ("element", "")))
            for (target, overrides), name in problems.items()]
    return fem + ours


def extra(summary: dict) -> dict:
    """The tip probe's displacements (the probe named tip, else the first) and the strain energy where the method
    reports it."""
    tip = _tip(summary.get("probes", {}))
    return {"tip_ux": tip.get("ux", np.nan), "tip_uy": tip.get("uy", np.nan),
            "strain_energy": summary.get("strain_energy", np.nan)}


def _tip(probes: dict) -> dict:
    """The probe named tip, else the first; {} without probes (a summary's and a golden file's alike)."""
    return probes.get("tip") or next(iter(probes.values()), {})


def three_codes(df: pd.DataFrame) -> pd.DataFrame:
    """Per golden case: CTM-RPIM's, scikit-fem's and FEniCSx's errors (L2, energy) and tip uy, and scikit-fem
    against FEniCSx (strain energy and tip uy, relative)."""
    ok = df[df.status == "ok"]
    rows = []
    for g in CASES:
        golden = read(g)
        fem = ok[(ok.case == g.name) & (ok.method == f"fem-{g.element}")]
        ours = ok[(ok.case == g.name.rsplit("-", 1)[0]) & ok.method.str.startswith("ctm-rpim")]
        if fem.empty or ours.empty:
            continue
        fem, ours = fem.iloc[0], ours.iloc[0]
        tip = _tip(golden["probes"]).get("uy", np.nan)
        errors = golden.get("errors", {})
        rows.append({"case": g.name, "element": g.element, "nodes": int(ours.nodes),
                     "ctm-rpim_l2": ours.l2_error, "ctm-rpim_energy": ours.energy_error, "ctm-rpim_tip_uy": ours.tip_uy,
                     "scikit-fem_l2": fem.l2_error, "scikit-fem_energy": fem.energy_error, "scikit-fem_tip_uy": fem.tip_uy,
                     "fenicsx_l2": errors.get("l2", np.nan), "fenicsx_energy": errors.get("energy", np.nan),
                     "fenicsx_tip_uy": tip,
                     "energy_skfem_vs_fenicsx": abs(fem.strain_energy / golden["strain_energy"] - 1.0),
                     "tip_skfem_vs_fenicsx": abs(fem.tip_uy - tip) / abs(tip) if tip else np.nan,
                     "dolfinx": golden["versions"]["dolfinx"]})
    return pd.DataFrame(rows)


def converged_table(df: pd.DataFrame) -> pd.DataFrame:
    """Per converged series: FEniCSx's extrapolated value of each element with its error estimate and observed
    order, and CTM-RPIM's value on the problem's own nodes with its relative distance from the P3 value."""
    ok = df[(df.status == "ok") & df.method.str.startswith("ctm-rpim")]
    series = json.loads(CONVERGED.read_text())["series"]
    rows = []
    for name, (_, component) in CONVERGED_CASES.items():
        ours = ok[ok.case == name]
        for s in series[name]:
            r = s[component]["richardson"]
            value = float(ours[f"tip_{component}"].iloc[0]) if len(ours) else np.nan
            rows.append({"case": name, "component": f"tip {component}", "element": s["element"],
                         "finest_mesh": s["meshes"][-1], "converged": r["value"], "estimated_error": r["error"],
                         "observed_order": r["order"], "ctm-rpim": value,
                         "ctm-rpim_nodes": int(ours.nodes.iloc[0]) if len(ours) else 0,
                         "ctm-rpim_rel_diff": value / r["value"] - 1.0})
    return pd.DataFrame(rows)


@cache
def fenicsx_linear() -> pd.DataFrame:
    """The committed FEniCSx results of the linear golden cases: the benchmark (``target``), the scikit-fem method
    of the same element (``fem-ELEMENT``), the node count, the plane state, and FEniCSx's errors against the exact
    solution: the tip probe's u_y (by the studies' rule, :func:`ctmrpim.result.probe_errors`), L2 and energy."""
    from ctmrpim.result import probe_errors

    rows = []
    for g in CASES:
        if not g.linear:
            continue
        golden, problem = read(g), g.load().problem
        errors = golden.get("errors", {})
        tip = probe_errors(problem, golden["probes"]).get("tip", {}).get("uy", np.nan)
        rows.append({"target": g.target, "method": f"fem-{g.element}", "nodes": len(golden["mesh"]["points"]),
                     "plane": problem.plane, "fenicsx_tip_error": tip, "fenicsx_l2_error": errors.get("l2", np.nan),
                     "fenicsx_energy_error": errors.get("energy", np.nan)})
    return pd.DataFrame(rows)


#: the FEniCSx columns :func:`with_fenicsx` adds
FENICSX_ERRORS = ("fenicsx_tip_error", "fenicsx_l2_error", "fenicsx_energy_error")


def with_fenicsx(table: pd.DataFrame, target: str, columns: tuple[str, ...] = FENICSX_ERRORS) -> pd.DataFrame:
    """``table`` (a study's rows of benchmark ``target``) with FEniCSx's errors beside each scikit-fem row that has
    a committed FEniCSx result on the same mesh and element (same method and node count, and plane state where the
    table has one); empty elsewhere."""
    fx = fenicsx_linear()
    fx = fx[fx.target == target]
    keys = ["method", "nodes"] + (["plane"] if "plane" in table else [])
    fx = fx[keys + list(columns)].drop_duplicates(keys)
    return table.merge(fx, on=keys, how="left") if len(fx) else table.assign(**{c: np.nan for c in columns})


def converged_tip_load() -> dict:
    """The converged FEniCSx tip of the neo-Hookean tip load (the highest element order of
    ``converged.json``): element, finest mesh, ux and uy (m) with their Richardson error estimates."""
    s = max(json.loads(CONVERGED.read_text())["series"]["tip-load"], key=lambda s: s["element"])
    return {"element": s["element"], "finest_mesh": s["meshes"][-1],
            **{c: s[c]["richardson"]["value"] for c in ("ux", "uy")},
            **{f"{c}_error": s[c]["richardson"]["error"] for c in ("ux", "uy")}}


def figure(df: pd.DataFrame) -> Figure:
    """The energy-norm error of the three codes on each case with an exact solution, and scikit-fem's distance
    from FEniCSx."""
    t = three_codes(df)
    fig, axes = new_figure(2, 7.0)
    exact = t[t.fenicsx_energy.notna() & (t.fenicsx_energy > 0)].reset_index(drop=True)
    x = np.arange(len(exact))
    for k, code in enumerate(("ctm-rpim", "scikit-fem", "fenicsx")):
        axes[0, 0].bar(x + (k - 1) * 0.27, 100 * exact[f"{code}_energy"], 0.27, label=code)
    axes[0, 0].set_yscale("log")
    axes[0, 0].set_xticks(x, exact.case, rotation=60, fontsize=7)
    axes[0, 0].set(ylabel="energy-norm error [%]", title="Each code against the exact solution")
    y = np.arange(len(t))
    axes[0, 1].semilogy(y, t.energy_skfem_vs_fenicsx, "o", label="strain energy")
    axes[0, 1].semilogy(y, t.tip_skfem_vs_fenicsx, "s", label="tip uy")
    axes[0, 1].set_xticks(y, t.case, rotation=60, fontsize=7)
    axes[0, 1].set(ylabel="|scikit-fem / FEniCSx - 1| [-]", title="scikit-fem against FEniCSx, same mesh")
    return finished(fig, axes)


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
