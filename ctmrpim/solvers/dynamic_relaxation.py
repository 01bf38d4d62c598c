"""Dynamic relaxation: explicit central differences with local damping (Section 2.1.4, Eqs. 9-11).

    M dv/dt = F_ext - F_int(U) + F_damp,      F_damp = -f |F_ext - F_int| sign(v)          (Eq. 11)

integrated with the half-step velocity, v_{n+1/2} = v_{n-1/2} + dt M^-1 F_n, U_{n+1} = U_n + dt v_{n+1/2},
the stress updated at every step by the return mapping of that step's strain increment (so the path is
a pseudo-time path, as in FLAC). For a static answer the mass is fictitious: with dt = 1 each node gets
m = SAFETY x sum_j |K_ij| over the rows of its two dofs in the elastic stiffness (Gershgorin, Underwood
1983), which bounds omega_max dt by 2 / sqrt(2 SAFETY) < 2, so the scheme is stable whatever the cloud.
The run is **at rest** when |F_ext - F_int| <= tolerance |F_ext|; a run still moving after ``steps``
steps has **not come to rest**: the paper's failure criterion for the slope (its displacement grows
without bound, Fig. 19a), a level's answer in a strength-reduction search; in an analysis of its own
(``analysis = "dynamic"``) the static answer was not found, and the command line reports it as a solve that
did not converge (:func:`not_at_rest`, exit status 3). A run whose forces stop being finite has diverged:
a :class:`~ctmrpim.errors.ConvergenceError` with the history up to there, whichever analysis it serves.
Each step is shown by the progress reporter (:mod:`ctmrpim.progress`).

True explicit dynamics (density mass, real time step, no damping) is issue 7's; this module serves the
stability problems of the paper (slope and footing), where the paper uses dynamic relaxation.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ctmrpim import progress
from ctmrpim.errors import ConvergenceError
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.problem.settings import Relaxation
from ctmrpim.solvers.plastic_system import PlasticSystem

#: Fictitious mass per node = SAFETY x the largest absolute row sum of its dofs' elastic stiffness rows.
SAFETY = 1.0


@dataclass
class RelaxationPath:
    """The outcome of :func:`relax`: at rest or not, the steps run, the final out-of-balance ratio and the
    recorded history."""
    at_rest: bool
    steps: int
    residual: float                                   # |F_ext - F_int| / |F_ext| at the end
    history: list[dict] = field(default_factory=list)   # step, max_displacement, residual

    def growth(self) -> float:
        """Relative growth of the maximum displacement over the last quarter of the steps run."""
        if not self.history:
            return 0.0
        mark = next(h for h in self.history if h["step"] >= 0.75 * self.steps)
        end = self.history[-1]["max_displacement"]
        return (end - mark["max_displacement"]) / max(mark["max_displacement"], 1e-300)


def max_displacement(U: np.ndarray) -> float:
    """The largest nodal displacement of interleaved dofs U (2n,)."""
    return float(np.linalg.norm(U.reshape(-1, 2), axis=1).max())


def relaxation_mass(system: PlasticSystem) -> np.ndarray:
    """(2n,) per dof: the fictitious nodal mass (equal for a node's two dofs) of ``system``, a
    :class:`~ctmrpim.solvers.plastic_system.PlasticSystem`."""
    K = abs(system.elastic_stiffness())
    rows = np.asarray(K.sum(axis=1)).ravel()          # dofs are interleaved (x, y) per node
    return SAFETY * np.repeat(rows.reshape(-1, 2).max(axis=1), 2)


def relax(system: PlasticSystem, material: MohrCoulomb, load_factor: float, settings: Relaxation,
          fixed_values: np.ndarray | None = None) -> RelaxationPath:
    """Relax the ``system`` (a :class:`~ctmrpim.solvers.plastic_system.PlasticSystem`) from its committed state
    under the loads at ``load_factor`` with ``material``; the state is committed at every step. Prescribed
    displacements are set at once (to ``load_factor`` times their values unless ``fixed_values``, one per
    fixed dof, is given)."""
    mass = relaxation_mass(system)
    f_ext = system.external_force(load_factor)
    scale = max(float(np.linalg.norm(f_ext)), 1e-30)
    U = system.U.copy()
    U[system.fixed] = load_factor * system.fixed_values if fixed_values is None else fixed_values
    v = np.zeros_like(U)
    history: list[dict] = []
    ratio = np.inf
    report = progress.current()
    # a run that blows up is reported once, as divergence, not by numpy's overflow warnings on the way
    with np.errstate(over="ignore", invalid="ignore"):
        for step in range(1, settings.steps + 1):
            system.commit(material, U)
            r = f_ext - system.internal_force()
            r[system.fixed] = 0.0
            ratio = float(np.linalg.norm(r)) / scale
            if not np.isfinite(ratio):
                history.append({"step": step, "max_displacement": max_displacement(U), "residual": ratio,
                                "note": "diverged: non-finite forces"})
                report.status("")
                raise ConvergenceError(f"dynamic relaxation diverged at step {step} (non-finite forces)",
                                       key="dynamic", history=history)
            report.status(f"dynamic relaxation: step {step}/{settings.steps}, out-of-balance force {ratio:.2e} "
                          f"of the loads (at rest below {settings.tolerance:g})")
            at_rest = ratio <= settings.tolerance
            if step % settings.record_every == 0 or at_rest or step == settings.steps:
                history.append({"step": step, "max_displacement": max_displacement(U), "residual": ratio})
            if at_rest:
                report.status("")
                return RelaxationPath(True, step, ratio, history)
            v += (r - settings.damping * np.abs(r) * np.sign(v)) / mass
            v[system.fixed] = 0.0
            U = U + v
    report.status("")
    return RelaxationPath(False, settings.steps, ratio, history)


def not_at_rest(outcome: dict[str, Any], history: list[dict], settings: Relaxation | None
                ) -> ConvergenceError | None:
    """The failure of a dynamic-relaxation analysis (its result's ``outcome`` and ``history``, solved with
    ``settings``) that is not at rest after its steps, with the history, its last record marked; None for
    a run at rest or another analysis. A strength-reduction level still moving is an answer, not this."""
    relaxed = outcome.get("relaxation")
    if relaxed is None or relaxed["at_rest"]:
        return None
    tolerance = f" = {settings.tolerance:g}" if settings is not None else ""
    marked = [dict(h) for h in history]
    if marked:
        marked[-1]["note"] = "not at rest"
    return ConvergenceError(f"dynamic relaxation did not come to rest in {relaxed['steps']} steps (out-of-balance "
                            f"force {relaxed['residual']:.2e} of the loads, above dynamic.tolerance{tolerance}); "
                            "raise dynamic.steps, or look for a mechanism", key="dynamic.steps", history=marked)
