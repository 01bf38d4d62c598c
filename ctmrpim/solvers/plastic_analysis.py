"""A quasi-static Mohr-Coulomb analysis of a :class:`~ctmrpim.solvers.plastic_system.PlasticSystem` on any
discretisation, written as a Result: the load path (up to the limit load with ``loading.until_failure``), the
strength reduction, or the dynamic relaxation of the loads applied at once; :class:`PlasticOutput` is how the
discretisation (CTM-RPIM nodes or mesh vertices) reports the system's state."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ctmrpim.materials.mohr_coulomb import ELASTIC, equivalent_plastic_strain
from ctmrpim.problem.case import Case
from ctmrpim.result import Result
from ctmrpim.solvers.dynamic_relaxation import relax
from ctmrpim.solvers.limit_criteria import SettlementCriterion, limit_load
from ctmrpim.solvers.plastic_system import PlasticSystem
from ctmrpim.solvers.strength_reduction import solve_strength_reduction
from ctmrpim.timing import Timer


@dataclass
class PlasticOutput:
    """How a discretisation reports a :class:`PlasticSystem`'s state (CTM-RPIM nodes or mesh vertices)."""

    method: str
    points: np.ndarray                                          # (n, 2) output points
    cells: list
    displacement: Callable[[np.ndarray], np.ndarray]            # U -> (n, 2) at the points
    nodal: Callable[[np.ndarray], np.ndarray]                   # (m, k) at the integration points -> (n, k)
    average: Callable[[np.ndarray], np.ndarray]                 # the same, a non-negative weighted mean of them
    probe_values: Callable[[np.ndarray, np.ndarray], dict]      # (U, stress (m, 3)) -> {name: probe record}
    peak_traction: float                                        # largest traction magnitude at full load
    counts: dict[str, Any]
    parameters: dict[str, Any]

    def plastic_field(self, plastic_strain: np.ndarray) -> dict[str, np.ndarray]:
        """Point data ``plastic_strain``: the equivalent plastic strain of (m, 4) point values, at the points,
        by ``average``: a projection that can overshoot would show negative plastic strain beside a shear band."""
        return {"plastic_strain": self.average(equivalent_plastic_strain(plastic_strain)[:, None])[:, 0]}

    def nodal_stress(self, stress: np.ndarray) -> dict[str, np.ndarray]:
        """``stress`` (n, 3: sxx, syy, sxy) and ``stress_zz`` (n,) at the points of the (m, 4: xx, yy, xy, zz)
        stresses at the integration points."""
        nodal = self.nodal(stress)
        return {"stress": nodal[:, :3], "stress_zz": nodal[:, 3]}


def run_elastoplastic(case: Case, system: PlasticSystem, out: PlasticOutput, timer: Timer,
                      progress: Callable[[Any], None] = lambda level: None) -> Result:
    """Load-stepped solve of a quasi-static Mohr-Coulomb Case (gravity ramped with the load factor; with
    ``loading.until_failure`` up to the limit load), or its strength reduction (``progress`` gets each
    level), on any discretisation."""
    material = case.problem.material
    series: list[dict] = []

    def on_converged(factor: float, U: np.ndarray) -> dict:
        series.append({"load_factor": factor, "u": out.displacement(U), **out.nodal_stress(system.stress),
                       "fields": out.plastic_field(system.plastic_strain)})
        record = {"plastic_points": int((system.region != ELASTIC).sum())}
        for name, rec in out.probe_values(U, None).items():
            record[name] = {k: rec[k] for k in ("x", "y", "ux", "uy")}
        return record

    if case.problem.analysis == "strength-reduction":
        n = len(out.points)
        base = Result(method=out.method, points=out.points, u=np.zeros((n, 2)), stress=np.zeros((n, 3)),
                      cells=out.cells, counts=dict(out.counts), timings=timer.total(), parameters=out.parameters,
                      defaults=case.defaults)
        return solve_strength_reduction(case, system, out, base, progress)
    if case.problem.analysis == "dynamic":
        return _relaxed(case, system, out, timer)
    criterion = (SettlementCriterion.build(system, case.loading.limit_slope)
                 if case.loading.until_failure and case.loading.limit_slope > 0 else None)
    path = system.run(case.loading, lambda t: material, lambda t: t, on_converged,
                      stop_on_failure=case.loading.until_failure, judge=criterion,
                      recheck=case.loading.until_failure)
    timer.lap("solve")
    probes = out.probe_values(path.U, system.stress[:, :3])
    stress = out.nodal_stress(system.stress)
    fields = out.plastic_field(system.plastic_strain)
    timer.lap("postprocess")
    counts = {**out.counts, "load_increments": sum(h["converged"] for h in path.history),
              "cutbacks": path.cutbacks, "newton_iterations": path.newton_iterations,
              "plastic_points": int((system.region != ELASTIC).sum()), **system.iteration_counts()}
    return Result(
        method=out.method, points=out.points, u=out.displacement(path.U), **stress, cells=out.cells,
        probes=probes, errors={}, counts=counts, timings=timer.total(), history=path.history, series=series,
        outcome=limit_load(path, out.peak_traction, criterion) if case.loading.until_failure else {},
        fields=fields, parameters=out.parameters, defaults=case.defaults)


def _relaxed(case: Case, system: PlasticSystem, out: PlasticOutput, timer: Timer) -> Result:
    """Dynamic relaxation of the loads applied at once (``analysis = "dynamic"``)."""
    path = relax(system, case.problem.material, 1.0, case.relaxation)
    timer.lap("solve")
    stress = system.stress[:, :3]
    result = Result(
        method=out.method, points=out.points, u=out.displacement(system.U), **out.nodal_stress(system.stress),
        cells=out.cells,
        probes=out.probe_values(system.U, stress), errors={},
        counts={**out.counts, "steps": path.steps, "plastic_points": int((system.region != ELASTIC).sum())},
        timings={}, history=path.history,
        fields=out.plastic_field(system.plastic_strain),
        outcome={"relaxation": {"at_rest": path.at_rest, "steps": path.steps, "residual": path.residual}},
        parameters=out.parameters, defaults=case.defaults)
    timer.lap("postprocess")
    result.timings = timer.total()
    return result


