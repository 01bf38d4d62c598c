"""The result of one solve, the same shape whichever method produced it (CTM-RPIM or scikit-fem)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ctmrpim.problem.model import Problem

STRESS_NAMES = ("sxx", "syy", "sxy")


@dataclass
class Result:
    """The result of one solve at n output points (field nodes or mesh vertices), whichever method produced it."""
    method: str                       # "ctm-rpim", "fem-q1", "fem-p1", "fem-p2"
    points: np.ndarray                # (n, 2) field nodes / mesh vertices
    u: np.ndarray                     # (n, 2) displacement at the points
    stress: np.ndarray                # (n, 3) sxx, syy, sxy at the points
    cells: list[tuple[str, np.ndarray]] = field(default_factory=list)  # meshio cell blocks (boundary lines, elements)
    probes: dict[str, dict[str, float]] = field(default_factory=dict)
    errors: dict[str, Any] = field(default_factory=dict)
    counts: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    parameters: dict[str, Any] = field(default_factory=dict)   # fully resolved input and derived values
    defaults: list[str] = field(default_factory=list)          # defaults that were applied
    history: list[dict[str, Any]] = field(default_factory=list)  # one entry per load increment
    series: list[dict[str, Any]] = field(default_factory=list)   # per converged increment: load_factor, u, stress
    fields: dict[str, np.ndarray] = field(default_factory=dict)  # further nodal fields (plastic strain ...)
    outcome: dict[str, Any] = field(default_factory=dict)        # headline results (factor_of_safety ...)


def probe_record(x: float, y: float, u: np.ndarray, s: np.ndarray) -> dict[str, float]:
    """A probe's record: its position (x, y), displacement u (2,): ux, uy and stress s (3,): sxx, syy, sxy."""
    return {"x": float(x), "y": float(y), "ux": float(u[0]), "uy": float(u[1]),
            **{k: float(v) for k, v in zip(STRESS_NAMES, s)}}


def probe_errors(problem: Problem, probes: dict[str, dict[str, float]]) -> dict[str, dict[str, float]]:
    """Relative error at each probe: of the displacement vector, and of each non-zero exact component."""
    exact = problem.exact
    if exact is None:
        return {}
    out: dict[str, dict[str, float]] = {}
    for name, rec in probes.items():
        x, y = np.array([rec["x"]]), np.array([rec["y"]])
        errs: dict[str, float] = {}
        ue = exact.displacement(x, y)
        if ue is not None:
            ue = ue[0]
            uh = np.array([rec["ux"], rec["uy"]])
            if np.linalg.norm(ue) > 0:
                errs["u"] = float(np.linalg.norm(uh - ue) / np.linalg.norm(ue))
            for k, ve, vh in zip(("ux", "uy"), ue, uh):
                if abs(ve) > 1e-12 * np.linalg.norm(ue):
                    errs[k] = float(abs(vh / ve - 1.0))
        se = exact.stress(x, y)
        if se is not None:
            for k, ve in zip(STRESS_NAMES, se[0]):
                if abs(ve) > 1e-12 * np.abs(se).max():
                    errs[k] = float(abs(rec[k] / ve - 1.0))
        out[name] = errs
    return out
