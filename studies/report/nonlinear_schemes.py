"""The section of the integration schemes on the nonlinear benchmarks: the paper's CTM against the consistent
one, per benchmark and formulation, with the difference and the cost, every number read from the study's rows."""
from __future__ import annotations

import numpy as np
import pandas as pd

import studies
from ctmrpim.problem.settings import DEFAULT_INTEGRATION
from studies.nonlinear_schemes import comparison
from studies.report.markdown import Writer, md
from studies.schemes import CONSISTENT, PAPER

#: two distances from the reference closer than this (absolute, as fractions) count as neither closer
SAME = 1e-4


def write_nonlinear_schemes(w: Writer, df: pd.DataFrame) -> None:
    """The comparison table (:func:`studies.nonlinear_schemes.comparison`), which scheme is closer where, what was
    refused and why, and the defaults the code applies."""
    w("## Integration schemes on the nonlinear benchmarks (not in the paper)\n\n")
    w(studies.study("nonlinear_schemes").__doc__.strip() + "\n\n")
    t = comparison(df)
    shown = t.assign(**{c: t[c].map(lambda v: "" if np.isnan(v) else f"{100 * v:+.3f} %")
                        for c in (PAPER, CONSISTENT, "difference")},
                     ctm_time_s=t.ctm_time_s.map(lambda v: f"{v:.1f}"),
                     time_ratio=t.time_ratio.map(lambda v: "" if np.isnan(v) else f"{v:.2f}"),
                     refused=t.refused.map(lambda v: "refused" if v else ""))
    w(md(shown.drop(columns=["reference"])) + "\n\n")
    ran = t[t.refused == ""]
    gain = np.abs(ran[PAPER]) - np.abs(ran[CONSISTENT])
    for formulation, g in gain.groupby(ran.formulation, sort=False):
        names = ran.benchmark[g.index]
        verdict = _verdict(g.to_numpy())
        w(f"{formulation}: {verdict} (" + ", ".join(f"{b} {100 * v:+.3f} %" for b, v in zip(names, g))
          + f" closer with {CONSISTENT}; time x{ran.time_ratio[g.index].min():.2f} to "
          f"x{ran.time_ratio[g.index].max():.2f}). ")
    for _, r in t[t.refused != ""].iterrows():
        w(f"{r.benchmark} ({r.formulation}) refuses {CONSISTENT}: \"{r.refused}\". ")
    nonlinear = sorted({a for a in ("quasi-static", "strength-reduction", "dynamic", "explicit")
                        if DEFAULT_INTEGRATION.get(a, PAPER) == PAPER})
    w(f"Default of the nonlinear analyses ({', '.join(nonlinear)}): {PAPER}; of linear analyses: "
      f"{DEFAULT_INTEGRATION.get('linear', PAPER)}.\n\n")
    w("![nonlinear schemes](nonlinear_schemes.png)\n\n")


def _verdict(gain: np.ndarray) -> str:
    """Which scheme is closer to the reference on a path's benchmarks, from the gains |ctm| - |ctm-vci|."""
    better, worse = gain > SAME, gain < -SAME
    if not (better.any() or worse.any()):
        return "the same"
    if better.any() and worse.any():
        return "mixed"
    winner = CONSISTENT if better.any() else PAPER
    return f"closer with {winner} on every benchmark" if (better | worse).all() else f"closer with {winner} or the same"
