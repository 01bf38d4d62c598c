"""Relative L2 displacement and energy-norm errors against an analytical solution.

Both solvers pass their own approximation evaluated at quadrature points of an *independent*, finer
rule over the exact geometry (never the integration points under test), so the numbers compare.
"""
from __future__ import annotations

import numpy as np

from ctmrpim.problem.model import Problem


def relative_errors(problem: Problem, xq: np.ndarray, wq: np.ndarray, u_h: np.ndarray,
                    stress_h: np.ndarray) -> dict[str, float]:
    """||u_h - u|| / ||u|| in L2, and sqrt(int e:C^-1:e) / sqrt(int s:C^-1:s) with e = s_h - s."""
    exact = problem.exact
    out: dict[str, float] = {}
    if exact is None:
        return out
    x, y = xq[:, 0], xq[:, 1]
    ue = exact.displacement(x, y)
    if ue is not None:
        out["l2"] = _ratio(np.sqrt(wq @ ((u_h - ue) ** 2).sum(1)), np.sqrt(wq @ (ue ** 2).sum(1)))
    se = exact.stress(x, y)
    if se is not None:
        C = np.linalg.inv(problem.D())
        de = stress_h - se
        num = wq @ np.einsum("pi,ij,pj->p", de, C, de)
        den = wq @ np.einsum("pi,ij,pj->p", se, C, se)
        out["energy"] = _ratio(np.sqrt(num), np.sqrt(den))
    return out


def _ratio(num: float, den: float) -> float:
    """num / den, NaN where the exact field is zero (a relative error is then undefined; summary.json writes
    it as null with a note)."""
    return float(num / den) if den > 0 else float("nan")
