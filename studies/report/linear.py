"""The linear sections: the cantilever (node density, time to accuracy, the method's parameters) and
the plate with a circular hole."""
from __future__ import annotations

import numpy as np
import pandas as pd

import studies
from studies.fe_references import FENICSX_ERRORS, fenicsx_linear, with_fenicsx
from studies.node_density import rates
from studies.report.markdown import Writer, md, pct

ERRORS = ("tip_error", "l2_error", "energy_error")
#: The parameter studies of the cantilever, each with its heading.
PARAMETER_STUDIES = (("integration_density", "Integration density (cf. Fig. 10)"),
                     ("support_radius", "Support radius (cf. Fig. 11)"),
                     ("shape_parameter", "Shape parameter (cf. Fig. 12)"),
                     ("parameter_map", "Support radius and shape parameter together (not in the paper)"))


def write_node_density(w: Writer, nd: pd.DataFrame) -> None:
    """Node density: CTM-RPIM against scikit-fem on the cantilever (Fig. 9), with the fitted rates."""
    w("## Node density: cantilever, CTM-RPIM against scikit-fem (cf. Fig. 9)\n\n")
    w("CTM-RPIM with eta = 5, r_c = 4 d_c, r_x = r_y = d_c/3, one Gauss point per sub-segment, linear or "
      "quadratic augmentation; scikit-fem Q1 quadrilaterals, P1 and P2 triangles on the same node grid. "
      "Times are wall seconds per solve on one core (sweep workers).\n\n")
    shown = with_fenicsx(nd, "cantilever")
    w(md(pct(shown, ERRORS + FENICSX_ERRORS)))
    w("\n\n")
    _fenicsx_agreement(w, shown)
    w(md(rates(nd).round(2)))
    ok = nd[nd.status == "ok"].set_index(["grid", "method"])
    at33 = ok.xs("33 x 9", level="grid")
    w(f"\n\n![node density](node_density.png)\n\nAt 33 x 9 nodes CTM-RPIM's tip error is "
      f"{at33.loc['fem-q1', 'tip_error'] / at33.loc['ctm-rpim', 'tip_error']:.1f} times smaller than Q1's, "
      f"as the paper claims; but P2 triangles on the same nodes are "
      f"{at33.loc['ctm-rpim', 'tip_error'] / at33.loc['fem-p2', 'tip_error']:.0f} times more accurate than "
      f"CTM-RPIM and {at33.loc['ctm-rpim', 'time_s'] / at33.loc['fem-p2', 'time_s']:.0f} times faster: on this "
      "smooth problem a quadratic finite element beats CTM-RPIM at equal nodes.\n\n")


def _fenicsx_agreement(w: Writer, shown: pd.DataFrame) -> None:
    """How far the FEniCSx columns of ``shown`` (:func:`studies.fe_references.with_fenicsx`) lie from scikit-fem's
    errors on the same rows."""
    both = shown[shown.fenicsx_energy_error.notna()]
    if both.empty:
        w("No committed FEniCSx result shares a mesh and element with this table's rows.\n\n")
        return
    gap = max(float((both[f"fenicsx_{c}"] - both[c]).abs().max()) for c in ERRORS)
    where = ", ".join(sorted({f"{m} at {n} nodes" for m, n in zip(both.method, both.nodes)}))
    w(f"The `fenicsx_*` columns are FEniCSx (dolfinx) on the same mesh and element, read from the committed golden "
      f"results (`reference_fem/golden/`, `python -m reference_fem.fenicsx_golden --check` re-solves them) where "
      f"they exist ({where}): its errors equal scikit-fem's to {gap:.1e} (absolute), so the finite-element "
      "column does not rest on scikit-fem alone.\n\n")


def write_time_to_accuracy(w: Writer, tta: pd.DataFrame) -> None:
    """Wall time to reach given tip errors (``tta``: ``time_to_accuracy.targets_table``), per method."""
    w("## Time to accuracy\n\n")
    w("Wall time per solve (one core) needed to reach a tip error of 1 %, 0.1 % and 0.01 %, interpolated "
      "in log-log between the grids that bracket it; empty where no grid of this run reached it.\n\n")
    w(md(tta.assign(**{c: tta[c].map(lambda v: "" if np.isnan(v) else f"{v:.3f} s") for c in tta.columns
                        if c != "method"})))
    t = tta.set_index("method")
    for col in [c for c in t.columns if c.startswith("time_to_")]:
        reached = t[col].dropna().sort_values()
        if len(reached) >= 2:
            w(f"\n\nFirst to {col[8:]}: {reached.index[0]}, {reached.iloc[1] / reached.iloc[0]:.1f} times sooner "
              f"than {reached.index[1]}.")
        elif len(reached) == 1:
            w(f"\n\nOnly {reached.index[0]} reaches {col[8:]} in this run.")
    for target in ("time_to_0.1%", "time_to_1%"):
        if not np.isnan(t.loc["ctm-rpim", target]):
            parts = [f"CTM-RPIM / {m}: x{t.loc['ctm-rpim', target] / t.loc[m, target]:.1f}"
                     for m in ("fem-q1", "fem-p2") if m in t.index and not np.isnan(t.loc[m, target])]
            w(f"\n\nTo reach {target[8:]}: " + ", ".join(parts) + " (above 1 means CTM-RPIM is slower).")
            break
    fx = fenicsx_linear()
    fx = fx[fx.target == "cantilever"]
    meshes = "; ".join(f"{n} nodes: {', '.join(d.method)}" for n, d in fx.groupby("nodes"))
    w(f" FEniCSx has no column here: its committed cantilever results are single meshes ({meshes}), and a time "
      "to accuracy needs a series of grids that brackets each target (its times would also hold the system "
      "interpreter's start-up and dolfinx's compilation).")
    w(" CTM-RPIM's time goes to the RPIM moment systems (one dense solve of about 50 unknowns per "
      "integration point, nine points per node) and the sparse products of the stiffness; see "
      "`python performance/bench_linear.py` for the per-phase split.\n\n![time to accuracy](time_to_accuracy.png)\n\n")


def write_parameter_studies(w: Writer, tables: dict[str, pd.DataFrame]) -> None:
    """One section per parameter study of the cantilever (Figs. 10-12 and the parameter map)."""
    for name, what in PARAMETER_STUDIES:
        module = studies.study(name)
        w(f"## {what}\n\n{module.__doc__.strip()}\n\n")
        parameter = getattr(module, "PARAMETER", None)
        if parameter in tables[name]:
            w(f"Values run: {parameter} = {', '.join(f'{v:g}' for v in sorted(tables[name][parameter].unique()))}.\n\n")
        w(md(pct(tables[name], ERRORS)))
        w(f"\n\n![{name}]({name}.png)\n\n")


def write_plate_hole(w: Writer, plate: pd.DataFrame) -> None:
    """The plate with a circular hole against Kirsch's solution."""
    w("## Plate with a circular hole (Kirsch)\n\n")
    w(f"{studies.study('plate_hole_convergence').__doc__.strip()}\n\n")
    shown = with_fenicsx(plate, "plate-hole", FENICSX_ERRORS[1:])
    w(md(pct(shown, ("l2_error", "energy_error") + FENICSX_ERRORS[1:]).drop(columns=["tip_error"])))
    w("\n\n")
    both = shown[shown.fenicsx_energy_error.notna()]
    if len(both):
        gap = max(float((both[f"fenicsx_{c}"] - both[c]).abs().max()) for c in ("l2_error", "energy_error"))
        w(f"FEniCSx on the same mesh and element (committed golden results: "
          f"{'; '.join(f'{m}, plane {pl}, {n} nodes' for m, pl, n in zip(both.method, both.plane, both.nodes))}) "
          f"gives the same errors as scikit-fem to {gap:.1e} (absolute).\n\n")
    w("![plate with hole](plate_hole_convergence.png)\n\n")
    ok = plate[(plate.status == "ok") & (plate.plane == "stress")]
    conc = ok.pivot(index="spacing", columns="method", values="sxx_hole_top") / 1000.0
    w("Stress concentration sxx(0, a) / T (exact 3), plane stress, by node spacing:\n\n")
    w(md(conc.sort_index(ascending=False).round(3).reset_index()))
    energy = ok.pivot(index="spacing", columns="method", values="energy_error")
    finest = energy.index.min()
    paper, default, p2 = (energy.loc[finest, m] for m in ("ctm-rpim", "ctm-rpim-vci", "fem-p2"))
    w(f"\n\nAt spacing {finest:g} the default scheme's energy-norm error is {paper / default:.1f} times smaller "
      f"than the paper's scheme's, and P2 finite elements on the same nodes are "
      f"{'more' if p2 < default else 'less'} accurate than the default ({p2:.2%} against {default:.2%}).")
    for method in ("ctm-rpim", "ctm-rpim-vci"):
        error = (conc[method].sort_index(ascending=False) - 3.0).abs().to_numpy()
        falls = bool(np.all(np.diff(error) < 0))
        w(f" {method}: the concentration's error {'falls' if falls else 'does not fall'} at every refinement of "
          f"this run ({', '.join(f'{e:.3f}' for e in error)}).")
    w("\n\n")


def write_integration_schemes(w: Writer, df: pd.DataFrame, table: pd.DataFrame) -> None:
    """The integration schemes side by side (``table``: ``integration_schemes.scheme_table``), with which wins
    where, every number read from the study's rows."""
    w("## Integration schemes side by side (not in the paper)\n\n")
    w(studies.study("integration_schemes").__doc__.strip() + "\n\n")
    shown = table.assign(
        patch_error=table.patch_error.map(lambda v: f"{v:.1e}"),
        energy_rate=table.energy_rate.map(lambda v: f"{v:.2f}"),
        finest_energy_error=table.finest_energy_error.map(lambda v: f"{100 * v:.3g} %"),
        jittered_energy_rate=table.jittered_energy_rate.map(lambda v: f"{v:.2f}"),
        jittered_finest_energy_error=table.jittered_finest_energy_error.map(lambda v: f"{100 * v:.3g} %"),
        manufactured_energy_rate=table.manufactured_energy_rate.map(lambda v: f"{v:.2f}"),
        manufactured_finest_energy_error=table.manufactured_finest_energy_error.map(lambda v: f"{100 * v:.3g} %"),
        **{"time_to_0.1%_energy_s": table["time_to_0.1%_energy_s"].map(lambda v: "not reached" if np.isnan(v)
                                                                         else f"{v:.3f} s")})
    w(md(shown))
    t = table.set_index("setting")
    exact = t.index[t.patch_error <= 1e-8].tolist()
    fastest = t["time_to_0.1%_energy_s"].dropna().sort_values()
    best_rate = t.energy_rate.idxmax()
    w(f"\n\nPatch test to round-off: {', '.join(exact) if exact else 'none'}; the others fail it by "
      f"{t.patch_error[t.patch_error > 1e-8].min():.1e} to {t.patch_error.max():.1e} (relative). "
      f"Highest energy-error rate: {best_rate} ({t.energy_rate[best_rate]:.2f}). ")
    if len(fastest):
        w(f"First to 0.1 % energy error on the cantilever: {fastest.index[0]} in {fastest.iloc[0]:.3f} s")
        w(f"; {', '.join(fastest.index[1:])} also reach it.\n\n" if len(fastest) > 1 else
          "; no other setting reaches it on these grids.\n\n")
    else:
        w("No setting reaches 0.1 % energy error on these grids.\n\n")
    for problem, name in (("jittered", "the jittered cantilever"), ("manufactured", "the manufactured solution")):
        finest = t[f"{problem}_finest_energy_error"].dropna().sort_values()
        if len(finest):
            rate = t[f"{problem}_energy_rate"]
            w(f"On {name}, finest energy error: " + ", ".join(
                f"{s} {100 * v:.3g} % (rate {rate[s]:.2f})" for s, v in finest.items()) + ".\n\n")
    ok = df[(df.status == "ok") & (df.problem == "plate-hole")]
    if len(ok):
        finest = ok[ok.h == ok.h.min()].set_index("setting")
        w(f"Plate with a hole at spacing {ok.h.min():g}, stress concentration sxx(0, a) / T (exact 3): "
          + ", ".join(f"{s} {v / 1000:.3f}" for s, v in finest.sxx_hole_top.items()) + ".\n\n")
    w("![integration schemes](integration_schemes.png)\n\n")
