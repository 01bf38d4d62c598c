"""The paper's claims as findings (issue 22, item 4): a claim holds when every measure meets the paper's limit,
does not hold when none does, holds partly otherwise; each measure has a regression pin."""
from __future__ import annotations

import pandas as pd

from studies import claims, tolerances


def test_every_measure_has_its_limits_in_the_table() -> None:
    for m in claims.MEASURES.values():
        assert "min" in tolerances.entry(m.judged_by) or "max" in tolerances.entry(m.judged_by), m
        assert "min" in tolerances.entry(m.pinned_by) or "max" in tolerances.entry(m.pinned_by), m
        assert tolerances.entry(m.described_by)["quantity"]


def test_outcome_of_a_claim() -> None:
    fig10 = next(c for c in claims.CLAIMS if c.where == "Fig. 10")
    good = {"integration-density-falls": 0.5, "integration-density-exponential": 0.9,
            "integration-density-17x5": 0.005, "integration-density-33x9": 0.003}
    assert claims.outcome(fig10, good) == claims.HOLDS
    assert claims.outcome(fig10, {**good, "integration-density-exponential": 0.2}) == claims.PARTLY
    bad = {"integration-density-falls": 1.5, "integration-density-exponential": 0.2,
           "integration-density-17x5": 0.05, "integration-density-33x9": 0.03}
    assert claims.outcome(fig10, bad) == claims.FAILS
    assert claims.outcome(fig10, {}) == ""


def test_stable_range_of_eta() -> None:
    """The widest run of eta values within the limit that holds the lower end of the paper's range."""
    lo = claims.stable_range_claimed()[0]
    sh = pd.DataFrame({"eta": [lo - 3, lo - 1, lo, lo + 1, lo + 2, lo + 3], "status": "ok",
                       "tip_error": [0.05, 0.002, 0.008, 0.007, 0.03, 0.009]})
    assert claims.stable_range(sh, 0.01) == (lo - 1, lo + 1)
    assert claims.stable_range(sh.assign(tip_error=0.02), 0.01) is None
