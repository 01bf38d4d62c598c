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
    # meshio cell blocks on the points: CTM-RPIM the tracked boundary ("line") then the body's triangles inside it
    # ("triangle", the alpha shape's); finite elements their elements ("triangle" or "quad")
    cells: list[tuple[str, np.ndarray]] = field(default_factory=list)
    probes: dict[str, dict[str, float]] = field(default_factory=dict)
    errors: dict[str, Any] = field(default_factory=dict)
    counts: dict[str, Any] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)
    parameters: dict[str, Any] = field(default_factory=dict)   # fully resolved input and derived values
    defaults: list[str] = field(default_factory=list)          # defaults that were applied
    history: list[dict[str, Any]] = field(default_factory=list)  # one entry per load increment
    # per converged increment: load_factor (or time), u, stress, stress_zz; where the solver re-tracks, also the
    # tracked "boundary" (e, 2) and its "triangles" (t, 3) on that increment's configuration
    series: list[dict[str, Any]] = field(default_factory=list)
    fields: dict[str, np.ndarray] = field(default_factory=dict)  # further nodal fields (plastic strain ...)
    outcome: dict[str, Any] = field(default_factory=dict)        # headline results (factor_of_safety ...)
    stress_zz: np.ndarray | None = None   # (n,) out-of-plane stress szz at the points; None: zero (plane stress)


def out_of_plane_stress(problem: Problem, stress: np.ndarray) -> np.ndarray:
    """(n,) szz of a linear-elastic in-plane stress ``stress`` (n, 3: sxx, syy, sxy): nu (sxx + syy) in plane
    strain (ezz = 0), zero in plane stress."""
    if problem.plane == "strain":
        return problem.material.nu * (stress[:, 0] + stress[:, 1])
    return np.zeros(len(stress))


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
