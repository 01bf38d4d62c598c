"""The large-deformation sections: the tip-loaded cantilever, the end moment rolling the beam into a
ring, and their deformed configurations."""
from __future__ import annotations

import re
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

import studies
from ctmrpim import benchmarks
from ctmrpim.reference.elastica import tip_load_elliptic
from studies import deformed_shapes, tolerances
from studies.fe_references import converged_table, converged_tip_load
from studies.report.full_results import full_table
from studies.report.markdown import Writer, md, sci, span


def write_tip_load(w: Writer, tip: pd.DataFrame, fe: pd.DataFrame | None = None,
                   out_dir: Path | None = None) -> None:
    """The tip-loaded cantilever against the elastica (Figs. 13-14), and the converged FEniCSx value of the
    continuum beam (with CTM-RPIM's distance from it from the three-codes study's rows ``fe``)."""
    w("## Large deflection: tip-loaded cantilever (cf. Figs. 13-14)\n\n")
    w(f"{studies.study('tip_load').__doc__.strip()}\n\n")
    tl = tip.drop(columns=["status", "d_c", "tip_error", "l2_error", "energy_error"],
                  errors="ignore")   # keep `method`: the table holds CTM-RPIM and FEM rows
    w(md(tl.assign(w_rel_diff=tl.w_rel_diff.map(lambda v: f"{100 * v:+.2f} %"),
                   u_rel_diff=tl.u_rel_diff.map(lambda v: f"{100 * v:+.2f} %"),
                   time_s=tl.time_s.map(lambda v: f"{v:.2f}"))))
    w("\n\n![tip load](tip_load.png)\n\n")
    ok = tip[tip.status == "ok"]
    shear = ok[ok.load == "end shear"]
    ours = shear[shear.method == "ctm-rpim"]
    tl, ul, p2 = (ours[ours.formulation == "TL"], ours[ours.formulation == "UL"],
                  shear[(shear.method == "fem-p2")])
    if len(p2) and len(tl):
        both = tl.set_index("lam").w_over_L / p2.set_index("lam").w_over_L - 1
        w(f"On {span(ok.nodes, 'd')} nodes (lambda = {', '.join(f'{v:g}' for v in sorted(ok.lam.unique()))} in this "
          "run): the continuum beam (W/L = 0.1) is slightly more flexible than the inextensible, shear-rigid "
          f"elastica: scikit-fem P2 on the same nodes (mesh-converged, `tip-load-fem-p2-mesh-convergence`) gives "
          f"{span(100 * p2.w_rel_diff, '+.1f')} % in w/L. The total-Lagrangian CTM-RPIM gives "
          f"{span(100 * tl.w_rel_diff, '+.1f')} %, so its own discretisation error is {span(100 * both, '+.1f')} % "
          "against P2. ")
    if len(ul):
        w("The adaptive updated-Lagrangian path (the paper's method) gives " + ", ".join(
            f"{100 * r.w_rel_diff:+.1f} % (lambda {r.lam:g})" for _, r in ul.sort_values("lam").iterrows())
          + ": every increment is solved on new CTM points laid over the bent beam, so its error need not be "
            "smooth in the load (`method.point_regeneration` carries the points with the body instead). ")
    corner = ok[(ok.load == "corner") & (ok.method == "ctm-rpim")]
    if len(corner) and len(ours):
        key = ["formulation", "lam"]
        ratio = corner.set_index(key).w_over_L / ours.set_index(key).w_over_L - 1
        exact = corner.set_index(key).w_over_L_exact / ours.set_index(key).w_over_L_exact - 1
        w(f"With the paper's corner load the tip deflects {span(100 * ratio.dropna(), '.1f')} % more, and the "
          f"elastica with the matching end moment predicts {span(100 * exact.dropna(), '.1f')} %. ")
    _converged(w, fe)
    full, state = full_table(out_dir, "tip_load")
    if full is not None and full is not tip:
        f = full[(full.status == "ok") & (full.load == "end shear")]
        parts = [f"{label} {span(100 * d.w_rel_diff, '+.2f')} %" for label, d in (
            ("total-Lagrangian CTM-RPIM", f[(f.method == "ctm-rpim") & (f.formulation == "TL")]),
            ("updated-Lagrangian CTM-RPIM", f[(f.method == "ctm-rpim") & (f.formulation == "UL")]),
            ("scikit-fem P2", f[f.method == "fem-p2"])) if len(d)]
        w(f"The full run (`reports/full/tip_load.csv`, {state}) at the paper's loads lambda = "
          f"{', '.join(f'{v:g}' for v in sorted(f.lam.unique()))} on {span(f.nodes, 'd')} nodes: w/L against the "
          f"elastica {'; '.join(parts)}. ")
        w("The UL run with carried points and the beam turned against the CTM lines are not committed as tables, "
          "so they are not quoted.\n\n")
        _full_figure(w, out_dir, "tip_load", state, "the paper's loads (cf. Fig. 14)")
    else:
        w("The paper's seven loads (full mode), the UL run with carried points and the beam turned against the CTM "
          "lines are not committed as tables (`reports/full/tip_load.csv`), so they are not quoted.\n\n")


def _converged(w: Writer, fe: pd.DataFrame | None) -> None:
    """The converged FEniCSx tip of the benchmark's own load against the elastica, and CTM-RPIM against it."""
    c = converged_tip_load()
    p = tomllib.loads(benchmarks.path("tip-load").read_text())["parameters"]
    lam, length = float(p["lam"]), float(p["L"])
    exact = tip_load_elliptic(lam)
    w_l, u_l = -c["uy"] / length, -c["ux"] / length
    w(f"The converged FEniCSx value of the continuum beam at the benchmark's own load, lambda = {lam:g} "
      f"({c['element'].upper()} on meshes up to {' x '.join(re.findall(r'[0-9]+', c['finest_mesh']))} nodes, "
      "Richardson; "
      f"`reference_fem/golden/converged.json`): w/L = {w_l:.6f} and u/L = {u_l:.6f} (estimated errors "
      f"{sci(c['uy_error'] / length, '.0e')} and {sci(c['ux_error'] / length, '.0e')} of L), "
      f"{w_l / exact.w_over_L - 1:+.2%} and {u_l / exact.u_over_L - 1:+.2%} from the elastica's {exact.w_over_L:.6f} "
      f"and {exact.u_over_L:.6f}: what the continuum beam differs from the elastica by, which no refinement "
      "removes. ")
    if fe is not None:
        t = converged_table(fe)
        t = t[(t.case == "tip-load") & (t.element == c["element"])]
        if len(t) and not np.isnan(t["ctm-rpim"].iloc[0]):
            r = t.iloc[0]
            w(f"CTM-RPIM on the benchmark's {int(r['ctm-rpim_nodes'])} nodes (default settings, the three-codes "
              f"study) lies {r['ctm-rpim_rel_diff']:+.3%} from it in u_y. ")


def write_end_moment(w: Writer, moment: pd.DataFrame, out_dir: Path | None = None) -> None:
    """The cantilever under an end moment against the exact circle (Figs. 16-17)."""
    w("## Large deflection: end moment (cf. Figs. 16-17)\n\n")
    w(f"{studies.study('end_moment').__doc__.strip()}\n\n")
    em = moment.drop(columns=["status", "d_c", "tip_error", "l2_error", "energy_error"],
                     errors="ignore")   # keep `method`: CTM-RPIM and FEM rows
    w(md(em.assign(time_s=em.time_s.map(lambda v: f"{v:.1f}"))))
    w("\n\n![end moment](end_moment.png)\n\n")
    ok = moment[moment.status == "ok"]
    limit = tolerances.entry("end-moment-ul-quarter")["max"]
    w(f"The issue asks for the tip within {limit:g} L at m = 0.25, 0.5 and 0.75 and, at the full moment, a "
      "closed ring (tip-root gap and mid-line within a few hundredths of L). ")
    for m, d in ok.groupby("m"):
        ctm, p2 = d[d.method == "ctm-rpim"], d[d.method == "fem-p2"]
        if len(ctm):
            w(f"At m = {m:g}: " + ", ".join(f"{r.formulation} {r.tip_distance_over_L:.4f} L"
                                            for _, r in ctm.iterrows())
              + (f" ({'all within' if (ctm.tip_distance_over_L <= limit).all() else 'not all within'} the target)"))
            if len(p2):
                w(f"; scikit-fem P2 on the same nodes {p2.tip_distance_over_L.iloc[0]:.4f} L, "
                  f"{ctm.tip_distance_over_L.min() / p2.tip_distance_over_L.iloc[0]:.0f} times closer than the "
                  "closest CTM-RPIM variant")
            w(". ")
    full, state = full_table(out_dir, "end_moment")
    if not (ok.m >= 1).any():
        ring = full[(full.status == "ok") & (full.m >= 1)] if full is not None else ()
        if len(ring):
            w(f"The ring, from the full run (`reports/full/end_moment.csv`, {state}): at m = {ring.m.max():g} the tip "
              "lies " + ", ".join(f"{r.tip_distance_over_L:.4f} L ({r.formulation} {r.method})"
                                  for _, r in ring.iterrows()) + " from the exact closed circle's. ")
        else:
            w("The ring (m up to 1: gap and mid-line) runs in full mode, and no full-mode table of it is committed "
              "(`reports/full/end_moment.csv`), so it is not quoted. ")
    w("How the moment is applied decides this benchmark: with tractions that each turn with their own boundary "
      "segment, a face that does not stay exactly straight turns its two tractions by slightly different angles, "
      "the couple gets a net force, and the ring's lever arm (up to L / pi) turns that into too much curvature - "
      "for scikit-fem P2 as much as for CTM-RPIM. The benchmark therefore turns both tractions with the end face "
      "as a whole (`follower = \"face\"`). What is left in the adaptive UL run is the rebuilds' own scatter: with "
      "the points carried (`method.point_regeneration`) the curve is smooth.\n\n")
    if full is not None and full is not moment:
        _full_figure(w, out_dir, "end_moment", state, "the moment up to the closed ring (cf. Fig. 17)")


def _full_figure(w: Writer, out_dir: Path | None, name: str, state: str, what: str) -> None:
    """The committed full-mode figure of study ``name`` (``out_dir/full/NAME.png``), beside the quick one above,
    with its provenance ``state``; nothing where the figure is not committed."""
    if out_dir is not None and (Path(out_dir) / "full" / f"{name}.png").is_file():
        w(f"The full-mode figure, {what} (`reports/full/{name}.png`, {state}):\n\n"
          f"![{name.replace('_', ' ')}, full mode](full/{name}.png)\n\n")


def write_deformed_shapes(w: Writer) -> None:
    """The section of the deformed-shapes figure (Figs. 15 and 17), which :func:`studies.deformed_shapes.run`
    draws."""
    w(f"### Deformed configurations (cf. Figs. 15 and 17)\n\n{deformed_shapes.__doc__.strip()}\n\n"
      f"![deformed shapes](deformed_shapes.png)\n\n")
