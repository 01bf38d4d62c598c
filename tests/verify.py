"""Checks against the tolerances table, shared by the verification tests."""
from __future__ import annotations

import numpy as np

from studies import tolerances
from studies.fitting import fitted_rate


def check(key: str, value: float) -> None:
    """``value`` within the limits of ``key`` in the tolerances table (the only place limits live)."""
    assert tolerances.passes(key, value), f"{key}: {value:.6g} outside {tolerances.describe_limit(key)}"


def check_rate(key: str, h, err) -> None:
    """Errors fall monotonically with h and their fitted rate is within the table's limits."""
    err = np.asarray(err, float)
    assert np.all(np.diff(err) < 0), f"{key}: errors do not fall monotonically: {err}"
    check(key, fitted_rate(h, err))
