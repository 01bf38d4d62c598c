"""Convergence rates fitted in log-log, as the tests and the report assert them."""
from __future__ import annotations

import numpy as np


def fitted_rate(h: np.ndarray, err: np.ndarray) -> float:
    """Slope p of log(err) = p log(h) + c (least squares)."""
    return float(np.polyfit(np.log(np.asarray(h, float)), np.log(np.asarray(err, float)), 1)[0])
