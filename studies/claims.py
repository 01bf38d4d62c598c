"""The paper's claims as findings: each claim, the numbers that judge it, computed from the study tables.

A claim is judged by one or more *measures*. Each measure is a number computed from a study's table and two
entries of the tolerances table: ``judged_by``, whose limit is what the paper claims (the paper's number), and
``pin``, the regression limit around the value we measured (the same entry where the claim holds and its limit
pins our value well enough). A claim *holds* when every measure meets the paper's limit, *does not hold* when none
does, and holds *partly* otherwise.

Both the tests (on the quick studies: each measure's value against its ``pin``) and the report (quick or full:
the findings, and the pins among its regression checks) call :func:`evaluate`, so a claim is measured one way
only. The claims are the paper's, so they are measured on its scheme's rows (``method.integration = "ctm"``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from studies import tolerances
from studies.schemes import PAPER


@dataclass(frozen=True)
class Measure:
    """One number that judges a claim: computed from study ``study``, the paper's limit in tolerance
    ``judged_by``, our regression limit in tolerance ``pin`` (``judged_by`` where not given)."""
    key: str
    study: str
    judged_by: str
    pin: str = ""

    @property
    def pinned_by(self) -> str:
        return self.pin or self.judged_by

    @property
    def described_by(self) -> str:
        """The tolerance whose ``quantity`` says what this measure is: the pin where it records a value the
        paper's limit does not describe (a single parameter value), else the paper's limit."""
        return self.pin if self.pin and not tolerances.entry(self.pin)["quantity"].startswith("the same") \
            else self.judged_by


@dataclass(frozen=True)
class Claim:
    """A claim of the paper (its figure and statement) and the measures that judge it."""
    where: str
    statement: str
    measures: tuple[Measure, ...]


CLAIMS = (
    Claim("Fig. 9", "CTM-RPIM is much more accurate than four-node FEM (Q1) at every node density",
          (Measure("ctmrpim-over-q1", "node_density", "claim-ctmrpim-beats-q1"),)),
    Claim("Fig. 10", "the error falls roughly exponentially as d_c/r grows, satisfactory from d_c/r = 3",
          (Measure("integration-density-falls", "integration_density", "claim-integration-density-falls"),
           Measure("integration-density-exponential", "integration_density",
                   "claim-integration-density-exponential", "claim-integration-density-exponential-measured"),
           Measure("integration-density-17x5", "integration_density", "claim-integration-density-17x5"),
           Measure("integration-density-33x9", "integration_density", "claim-integration-density-33x9"))),
    Claim("Fig. 11", "from r_c = 3.5 d_c the error is below 1.5 % and nearly stable; a larger support domain "
                     "gives a higher accuracy",
          (Measure("support-radius-below", "support_radius", "claim-support-radius"),
           Measure("support-radius-monotone", "support_radius", "claim-support-radius-monotone",
                   "claim-support-radius-monotone-measured"))),
    Claim("Fig. 12", "the error is low and stable for eta between 4.5 and 7.5",
          (Measure("shape-parameter-stable", "shape_parameter", "claim-shape-parameter-stable"),
           Measure("shape-parameter-eta75", "shape_parameter", "claim-shape-parameter-stable",
                   "claim-shape-parameter-eta75"))),
)
#: every measure by its key
MEASURES = {m.key: m for c in CLAIMS for m in c.measures}
#: the outcomes of a claim
HOLDS, PARTLY, FAILS = "holds", "partly", "does not hold"
#: the interval of d_c/r up to and from which the paper calls the accuracy satisfactory (Fig. 10)
SATISFACTORY = 3.0


def _ok(df: pd.DataFrame) -> pd.DataFrame:
    """The rows that ran, of the paper's scheme where the table has several."""
    ok = df[df.status == "ok"]
    return ok[ok.scheme == PAPER] if "scheme" in ok else ok


def _log_slope(x: pd.Series, y: pd.Series) -> float:
    """The slope of log(y) against x (least squares): the exponential rate of y in x."""
    return float(np.polyfit(np.asarray(x, float), np.log(np.asarray(y, float)), 1)[0])


def published_range(key: str) -> tuple[float, float]:
    """The paper's range of a parameter, from the tolerances table's reference value ``key`` (``values``)."""
    lo, hi = tolerances.entry(key)["values"]
    return float(lo), float(hi)


def evaluate(tables: dict[str, pd.DataFrame]) -> dict[str, float]:
    """Each measure's value (by measure key) from the study tables that are present."""
    out: dict[str, float] = {}
    nd = tables.get("node_density")
    if nd is not None:
        t = _ok(nd).pivot(index="grid", columns="method", values="tip_error")
        out["ctmrpim-over-q1"] = float((t["ctm-rpim"] / t["fem-q1"]).max())
    ig = tables.get("integration_density")
    if ig is not None:
        ig = _ok(ig)
        ratios, rate_ratios = [], []
        for _, d in ig.groupby("grid"):
            d = d.sort_values("dc_over_r")
            e = d[d.dc_over_r <= SATISFACTORY].tip_error.to_numpy()
            ratios.extend(e[1:] / e[:-1])
            before, after = d[d.dc_over_r <= SATISFACTORY], d[d.dc_over_r >= SATISFACTORY]
            if len(before) >= 2 and len(after) >= 2:
                rate_ratios.append(_log_slope(after.dc_over_r, after.tip_error)
                                   / _log_slope(before.dc_over_r, before.tip_error))
        out["integration-density-falls"] = float(np.max(ratios))
        if rate_ratios:
            out["integration-density-exponential"] = float(np.min(rate_ratios))
        for grid, key in (("17 x 5", "integration-density-17x5"), ("33 x 9", "integration-density-33x9")):
            d = ig[(ig.grid == grid) & (ig.dc_over_r >= SATISFACTORY)]
            if len(d):
                out[key] = float(d.tip_error.max())
    sr = tables.get("support_radius")
    if sr is not None:
        sr = _ok(sr).sort_values("rc_over_dc")
        from_ = sr[sr.rc_over_dc >= published_range("published-support-radius-range")[0]]
        out["support-radius-below"] = float(from_.tip_error.max())
        e = from_.tip_error.to_numpy()
        if len(e) >= 2:
            out["support-radius-monotone"] = float(np.max(e[1:] / e[:-1]))
    sh = tables.get("shape_parameter")
    if sh is not None:
        sh = _ok(sh)
        lo, hi = stable_range_claimed()
        inside = sh[(sh.eta >= lo) & (sh.eta < hi)]
        out["shape-parameter-stable"] = float(inside.tip_error.max())
        at = sh[np.isclose(sh.eta, hi)]
        if len(at):
            out["shape-parameter-eta75"] = float(at.tip_error.iloc[0])
    return out


def stable_range_claimed() -> tuple[float, float]:
    """The paper's range of eta with a low and stable error (Fig. 12), from the tolerances table."""
    return published_range("published-shape-parameter-range")


def stable_range(sh: pd.DataFrame, limit: float) -> tuple[float, float] | None:
    """The widest run of consecutive eta values of the shape-parameter table ``sh`` (paper's scheme) whose tip
    errors all lie within ``limit``, among those that contain the lower end of the paper's range; None if that
    value is not within ``limit``."""
    sh = _ok(sh).sort_values("eta")
    eta, ok = sh.eta.to_numpy(), (sh.tip_error <= limit).to_numpy()
    start = int(np.argmin(np.abs(eta - stable_range_claimed()[0])))
    if not ok[start]:
        return None
    lo = hi = start
    while lo > 0 and ok[lo - 1]:
        lo -= 1
    while hi < len(eta) - 1 and ok[hi + 1]:
        hi += 1
    return float(eta[lo]), float(eta[hi])


def outcome(claim: Claim, values: dict[str, float]) -> str:
    """Whether ``claim`` holds, holds partly or does not hold in ``values`` (its measures that were computed)."""
    met = [tolerances.passes(m.judged_by, values[m.key]) for m in claim.measures if m.key in values]
    if not met:
        return ""
    return HOLDS if all(met) else FAILS if not any(met) else PARTLY
