"""Limit loads read from the response (issue 19, item 2), for any discretisation of
:class:`~ctmrpim.solvers.plastic_system.PlasticSystem`: the footing's load-settlement criterion and the limit
load's record in summary.json. The strength reduction's criterion on the SRF-displacement curve lives with
its search (:mod:`ctmrpim.solvers.strength_reduction`)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ctmrpim.solvers.load_stepping import LoadPath
from ctmrpim.solvers.plastic_system import PlasticSystem


@dataclass
class SettlementCriterion:
    """Failure read from the load-settlement curve of a run ``until_failure`` (issue 19): the settlement is w =
    F . U / sum |F|, the displacement along the load F (the external force per unit load factor at the free dofs)
    averaged with the load's weights (under a uniform pressure, the mean settlement of the loaded boundary), the
    slope is that of the load factor against w, and an increment from the carried state a to b has failed when

        (lambda_b - lambda_a) / (w_b - w_a) < fraction x k_elastic,     k_elastic = 1 / w(K_elastic^-1 F),

    the slope of the purely elastic body. Method-agnostic: it needs the forces and the elastic stiffness only.
    Converging Newton iterations along the plateau do not count as carried (the consistent tangent of perfect
    plasticity converges far along it: 38 m of settlement on the phi = 20 deg footing), nor does an iteration
    cap that gives out before the knee count as failure without the re-check with more patience
    (:func:`~ctmrpim.solvers.load_stepping.step_loads`)."""

    direction: np.ndarray          # F / sum |F| (2n,), zero at the fixed dofs
    elastic_slope: float           # load factor per unit settlement of the elastic body
    fraction: float                # the slope ratio below which an increment has failed
    U0: np.ndarray                 # the state the loads start from (the settlement counts from it)

    @classmethod
    def build(cls, system: PlasticSystem, fraction: float) -> SettlementCriterion:
        """The criterion of ``system``'s loads (their increment from load factor 0 to 1)."""
        F = system.external_force(1.0) - system.external_force(0.0)
        F[system.fixed] = 0.0
        direction = F / max(np.abs(F).sum(), 1e-300)
        return cls(direction, 1.0 / float(direction @ system.elastic_response(F)), fraction, system.U.copy())

    def settlement(self, U: np.ndarray) -> float:
        """w of the dofs U (2n,)."""
        return float(self.direction @ (U - self.U0))

    def __call__(self, fa: float, Ua: np.ndarray, fb: float, Ub: np.ndarray) -> tuple[str | None, dict]:
        """(why the increment a -> b has failed or None, its settlement and slope ratio for the history)."""
        wa, wb = self.settlement(Ua), self.settlement(Ub)
        ratio = (fb - fa) / (wb - wa) / self.elastic_slope if wb > wa else math.inf
        record = {"settlement": wb, "slope_ratio": ratio if math.isfinite(ratio) else None}
        if ratio < self.fraction:
            return (f"settlement runaway (dq/dw = {ratio:.3g} of the elastic slope, below {self.fraction:g})",
                    record)
        return None, record

    def describe(self, peak_traction: float) -> dict[str, Any]:
        """The criterion as summary.json states it."""
        return {"rule": "an increment is carried when it reaches equilibrium (a non-convergence re-checked by Newton on "
                        "the consistent tangent with 8 times its cap) and the slope of pressure against settlement from the last carried "
                        "level, dq/dw, is at least loading.limit_slope times the elastic body's; the settlement is "
                        "the load-weighted mean displacement along the load",
                "limit_slope": self.fraction, "elastic_slope": self.elastic_slope * peak_traction,
                "elastic_slope_units": "pressure per unit settlement (load factor per unit settlement where no "
                                       "traction acts)"}


def limit_load(path: LoadPath, peak_traction: float, criterion: SettlementCriterion | None = None
               ) -> dict[str, Any]:
    """The limit load of a run ``until_failure``: the last load factor carried and the one that was not
    (None if the full load was carried), and the same as the peak traction on the loaded boundary (the
    limit pressure of a uniformly loaded footing); with the response ``criterion``, what decided the
    failure and the load-settlement curve (every state in equilibrium, carried or not)."""
    carried = max((h["load_factor"] for h in path.history if h["converged"]), default=0.0)
    failed = path.failed_at
    out: dict[str, Any] = {"limit_load_factor": {"carried": carried, "failed": failed},
                           "limit_pressure": {"carried": carried * peak_traction,
                                              "failed": None if failed is None else failed * peak_traction}}
    if criterion is None:
        return out
    last = path.history[-1] if path.history else {}
    at_carried = next((h for h in reversed(path.history) if h["converged"]), {})
    points = [h for h in path.history if "settlement" in h]
    out["limit_criterion"] = {
        **criterion.describe(peak_traction),
        "decided_by": (None if failed is None else
                       "settlement runaway" if last.get("equilibrium") else "non-convergence"),
        "settlement_at_carried": at_carried.get("settlement", 0.0),
        "slope_ratio_at_carried": at_carried.get("slope_ratio"),
        "settlement_at_failed": last.get("settlement") if failed is not None else None,
        "slope_ratio_at_failed": last.get("slope_ratio") if failed is not None else None}
    out["load_settlement"] = {"pressure": [h["load_factor"] * peak_traction for h in points],
                              "settlement": [h["settlement"] for h in points],
                              "carried": [bool(h["converged"]) for h in points]}
    return out
