"""The paper's claims as numbers computed from the study tables, keyed like the tolerances table.

Both the tests (on the quick studies) and the report (quick or full) call :func:`evaluate`, so a
claim is measured one way only. The claims are the paper's, so they are measured on its scheme's rows
(``method.integration = "ctm"``).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from studies.schemes import PAPER

#: claim key -> (study it needs, what the paper says, the tolerance whose limit is the paper's claim).
#: The last differs from the key where our tolerance records a measured *failure* of the claim.
CLAIMS = {
    "claim-ctmrpim-beats-q1": ("node_density", "CTM-RPIM beats four-node FEM (Q1) at equal nodes (Fig. 9)",
                               "claim-ctmrpim-beats-q1"),
    "claim-integration-density-falls": ("integration_density", "the error falls as d_c/r grows (Fig. 10)",
                                        "claim-integration-density-falls"),
    "claim-integration-density-17x5": ("integration_density", "satisfactory from d_c/r = 3 (Fig. 10a, 17 x 5)",
                                       "claim-integration-density-17x5"),
    "claim-integration-density-33x9": ("integration_density", "about 0.3 % from d_c/r = 3 (Fig. 10b, 33 x 9)",
                                       "claim-integration-density-33x9"),
    "claim-support-radius": ("support_radius", "below 1.5 % and stable from r_c = 3.5 d_c (Fig. 11)",
                             "claim-support-radius"),
    "claim-shape-parameter-stable": ("shape_parameter", "low and stable for eta in [4.5, 7.5] (Fig. 12)",
                                     "claim-shape-parameter-stable"),
    "claim-shape-parameter-eta75": ("shape_parameter", "eta = 7.5 is inside the stable range (Fig. 12)",
                                    "claim-shape-parameter-stable"),
}


def _ok(df: pd.DataFrame) -> pd.DataFrame:
    """The rows that ran, of the paper's scheme where the table has several."""
    ok = df[df.status == "ok"]
    return ok[ok.scheme == PAPER] if "scheme" in ok else ok


def evaluate(tables: dict[str, pd.DataFrame]) -> dict[str, float]:
    """Each claim's measured value from the study tables that are present."""
    out: dict[str, float] = {}
    nd = tables.get("node_density")
    if nd is not None:
        t = _ok(nd).pivot(index="grid", columns="method", values="tip_error")
        out["claim-ctmrpim-beats-q1"] = float((t["ctm-rpim"] / t["fem-q1"]).max())
    ig = tables.get("integration_density")
    if ig is not None:
        ig = _ok(ig)
        ratios = []
        for _, d in ig.groupby("grid"):
            d = d.sort_values("dc_over_r")
            e = d[d.dc_over_r <= 3.0].tip_error.to_numpy()
            ratios.extend(e[1:] / e[:-1])
        out["claim-integration-density-falls"] = float(np.max(ratios))
        for grid, key in (("17 x 5", "claim-integration-density-17x5"), ("33 x 9", "claim-integration-density-33x9")):
            d = ig[(ig.grid == grid) & (ig.dc_over_r >= 3.0)]  # ig holds the paper's scheme only
            if len(d):
                out[key] = float(d.tip_error.max())
    sr = tables.get("support_radius")
    if sr is not None:
        sr = _ok(sr)
        out["claim-support-radius"] = float(sr[sr.rc_over_dc >= 3.5].tip_error.max())
    sh = tables.get("shape_parameter")
    if sh is not None:
        sh = _ok(sh)
        out["claim-shape-parameter-stable"] = float(sh[(sh.eta >= 4.5) & (sh.eta <= 6.5)].tip_error.max())
        at75 = sh[np.isclose(sh.eta, 7.5)]
        if len(at75):
            out["claim-shape-parameter-eta75"] = float(at75.tip_error.iloc[0])
    return out
