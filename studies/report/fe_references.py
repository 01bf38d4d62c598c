"""The section of the three codes on the same problems: CTM-RPIM, scikit-fem and FEniCSx (the committed golden
results), and the converged FEniCSx values CTM-RPIM is measured against where no exact solution exists; every
number read from the study's rows and the golden files."""
from __future__ import annotations

import numpy as np
import pandas as pd

import studies
from studies.fe_references import converged_table, three_codes
from studies.report.markdown import Writer, md

#: an energy error below this is the exact field reproduced (round-off)
ROUND_OFF = 1e-8


def _sci(v: float) -> str:
    return "" if np.isnan(v) else f"{v:.3g}"


def write_fe_references(w: Writer, df: pd.DataFrame) -> None:
    """The three codes' table, the agreement of the two finite-element codes, and the converged values."""
    w("## Three codes on the same problems: CTM-RPIM, scikit-fem and FEniCSx (not in the paper)\n\n")
    w(studies.study("fe_references").__doc__.strip() + "\n\n")
    t = three_codes(df)
    if t.empty:
        w("No case ran.\n\n")
        return
    shown = t.drop(columns=["dolfinx"]).copy()
    for c in shown.columns[3:]:
        shown[c] = shown[c].map(_sci)
    w(md(shown) + "\n\n")
    linear = t[~t.case.str.startswith("tip-load")]
    nonlinear = t[t.case.str.startswith("tip-load")]
    w(f"FEniCSx: dolfinx {', '.join(sorted(set(t.dolfinx)))}. scikit-fem against FEniCSx on the same mesh and "
      f"element: strain energy within {linear.energy_skfem_vs_fenicsx.max():.1e} on the {len(linear)} linear "
      f"cases")
    if len(nonlinear):
        w(f" and {nonlinear.energy_skfem_vs_fenicsx.max():.1e} on the tip load (tip uy "
          f"{nonlinear.tip_skfem_vs_fenicsx.max():.1e})")
    exact = t[t["ctm-rpim_energy"].notna() & t["scikit-fem_energy"].notna()]
    both = exact[(exact["ctm-rpim_energy"] < ROUND_OFF) & (exact["scikit-fem_energy"] < ROUND_OFF)]
    exact = exact.drop(both.index)
    better = exact["ctm-rpim_energy"] < exact["scikit-fem_energy"]
    w(f". Against the exact solution CTM-RPIM's energy error is below the finite element's on the same nodes in "
      f"{better.sum()} of {len(exact)} cases ({', '.join(exact.case[better]) or 'none'}) and above it in "
      f"{', '.join(exact.case[~better]) or 'none'}; both reproduce the exact field to round-off in "
      f"{', '.join(both.case) or 'none'}.\n\n")
    c = converged_table(df)
    if len(c):
        w("Converged FEniCSx values (Richardson over the meshes up to the finest shown) and CTM-RPIM on the "
          "problem's own nodes:\n\n")
        shown = c.assign(converged=c.converged.map(lambda v: f"{v:.8g}"),
                         estimated_error=c.estimated_error.map(lambda v: f"{v:.1e}"),
                         observed_order=c.observed_order.map(lambda v: f"{v:.2f}"),
                         **{"ctm-rpim": c["ctm-rpim"].map(lambda v: f"{v:.6g}"),
                            "ctm-rpim_rel_diff": c["ctm-rpim_rel_diff"].map(lambda v: f"{100 * v:+.3f} %")})
        w(md(shown) + "\n\n")
    w("![fe references](fe_references.png)\n\n")
