"""The response criteria of limit loads and factors of safety (issue 19, item 2): their settings are checked
naming the key, and the footing's criterion reads the load-settlement slope against the elastic one."""
from __future__ import annotations

import numpy as np
import pytest

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.solvers.limit_criteria import SettlementCriterion


@pytest.mark.parametrize("target, change, key", [
    ("footing", "loading.limit_slope=1.0", "loading.limit_slope"),
    ("footing", "loading.limit_slope=-0.01", "loading.limit_slope"),
    ("footing", "loading.limit_slope=true", "loading.limit_slope"),
    ("slope", "strength-reduction.limit_growth=-1", "strength-reduction.limit_growth"),
])
def test_bad_criterion_settings_name_the_key(target: str, change: str, key: str) -> None:
    with pytest.raises(ProblemError, match=key.replace(".", r"\.")):
        benchmarks.load(target, [change])


def test_the_settlement_criterion_compares_the_slope_with_the_elastic_one() -> None:
    """w = F . U / sum |F| (a uniform load on two dofs: their mean displacement along it); an increment is not
    carried where its slope falls below the fraction of the elastic slope, and says why."""
    criterion = SettlementCriterion(direction=np.array([0.0, -0.5, 0.0, -0.5]), elastic_slope=100.0, fraction=0.01,
                                    U0=np.zeros(4))
    U = lambda w: np.array([0.0, -w, 0.0, -w])   # noqa: E731
    assert criterion.settlement(U(0.02)) == pytest.approx(0.02)
    verdict, record = criterion(0.5, U(0.005), 0.6, U(0.01))        # slope 20: 0.2 of the elastic
    assert verdict is None and record["slope_ratio"] == pytest.approx(0.2)
    verdict, record = criterion(0.5, U(0.005), 0.51, U(0.02))       # slope 0.67: below 0.01 x 100
    assert verdict.startswith("settlement runaway") and record["settlement"] == pytest.approx(0.02)
    verdict, record = criterion(0.5, U(0.005), 0.51, U(0.005))      # no settlement at all: carried
    assert verdict is None and record["slope_ratio"] is None
