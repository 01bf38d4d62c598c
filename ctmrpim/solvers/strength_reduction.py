"""Strength reduction (Section 3.3.1, Eqs. 38-39): the factor of safety of a body under gravity.

The strengths are divided by the strength reduction factor SRF,

    c' = c / SRF,       tan(phi') = tan(phi) / SRF,       tan(psi') = tan(psi) / SRF,

(the paper reduces c and phi; psi is reduced the same way so that psi' <= phi' stays true, with psi = 0
it stays 0; a tension cut-off, a strength like c, is divided by SRF too), and the body is equilibrated
under its full loads, by one of two solvers:

- ``solver = "newton"``: load stepping (:mod:`ctmrpim.solvers.load_stepping`); a level is **failed** when Newton
  cannot reach equilibrium: the SRF sub-step was cut back ``loading.max_cutbacks`` times, or until it was no
  wider than ``width`` (a narrower one cannot make the bracket any more useful: the search stops at that width),
  and still did not converge within ``loading.max_iterations`` iterations;
- ``solver = "dynamic-relaxation"`` (the paper's, :mod:`ctmrpim.solvers.dynamic_relaxation`): the reduction
  applied at once and relaxed; a level is **failed** when it is still moving after ``dynamic.steps``
  steps (not at rest, and its maximum displacement grew by more than ``SETTLED_GROWTH`` over the last
  quarter of the steps: the paper's "the displacement increases continuously").

The criterion is recorded with every level, with the maximum displacement (of the last iterate or
step at a failed level, where it grows without bound).

Search (``values`` empty): the gravity stage is solved once at SRF = ``start`` (loads ramped by the
load stepping), then SRF rises by ``step`` from the last stable state, each level continuing from the
converged state below it (as Kratos GeoMechanics and PLAXIS' Sum-Msf do); after the first failed level
the interval [stable, failed] is bisected, again from the last stable state, until it is at most
``width`` wide. The answer is the bracket [stable, failed], not one number.

Sweep (``values = [...]``): each SRF is solved on its own from zero, gravity ramped at the reduced
strength (Griffiths & Lane 1999); the paper's Fig. 19 plots these. The sweep study sends one case per
value through the sweep executor so the levels run in parallel.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Callable

import numpy as np

from ctmrpim import progress as _progress
from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.problem.case import Case
from ctmrpim.problem.settings import Loading, Relaxation, StrengthReduction
from ctmrpim.result import Result
from ctmrpim.solvers.dynamic_relaxation import max_displacement, relax
from ctmrpim.solvers.plastic_system import PlasticSystem
from ctmrpim.timing import Timer

CRITERION = {"newton": "displacement runaway or non-convergence: a level is failed when the largest nodal displacement "
                       "from the last stable level, per unit relative rise of the SRF, exceeds "
                       "strength-reduction.limit_growth times the largest displacement at SRF = start (the response: "
                       "the SRF-displacement curve turning flat), or when the equilibrium iteration (loading.tangent: "
                       "Newton, or the elastic stiffness with Anderson mixing) does not reach the residual and "
                       "displacement tolerance at an SRF sub-step cut back loading.max_cutbacks times or until it is no "
                       "wider than strength-reduction.width (where the iteration is "
                       "the elastic stiffness's, every sub-step it does not converge is handed over to Newton on the "
                       "consistent tangent before it is cut back), re-checked before it counts (by Newton on the "
                       "consistent tangent where the iteration was the elastic stiffness's, with 8 times its cap)",
             "dynamic-relaxation": "still moving: after dynamic.steps steps of dynamic relaxation the out-of-balance "
                                   "force is above dynamic.tolerance of the loads and the maximum displacement grew "
                                   "by more than 1 % over the last quarter of the steps (the paper's criterion: it "
                                   "keeps growing)"}
#: Dynamic relaxation: a level not at rest whose maximum displacement grew by at most this fraction over
#: the last quarter of its steps has settled (a slowly creeping stable level is not a failure).
SETTLED_GROWTH = 0.01


def reduced(material: MohrCoulomb, srf: float) -> MohrCoulomb:
    """The material with its strength divided by ``srf`` (Eqs. 38-39)."""
    def angle(a: float) -> float:
        return math.degrees(math.atan(math.tan(math.radians(a)) / srf))
    tension = None if material.tension is None else material.tension / srf
    return replace(material, c=material.c / srf, phi=angle(material.phi), psi=angle(material.psi), tension=tension)


@dataclass
class Level:
    """One strength-reduction level."""

    srf: float
    stable: bool
    iterations: int
    cutbacks: int
    seconds: float
    state: tuple[np.ndarray, ...]    # (U, stress, region, plastic strain): converged, or a failed level's last iterate
    criterion: str = ""              # a failed level: why; a stable one: how it was reached, where not its own
    path: list[list[float]] | None = None          # dynamic relaxation: [step, max displacement] as it ran
    growth: float | None = None      # the search: displacement from the stable level below per relative SRF rise,
                                     # in units of the displacement at SRF = start (the runaway measure)

    @property
    def max_displacement(self) -> float:
        """The largest nodal displacement of the level's state."""
        return max_displacement(self.state[0])

    def record(self) -> dict[str, Any]:
        """The level as an entry of the result's history: srf, stable, iterations, cut-backs, max displacement,
        seconds, and the criterion and displacement history where there are."""
        return {"srf": self.srf, "stable": self.stable, "iterations": self.iterations, "cutbacks": self.cutbacks,
                "max_displacement": self.max_displacement, "seconds": round(self.seconds, 3),
                **({"criterion": self.criterion} if self.criterion else {}),
                **({"growth": self.growth} if self.growth is not None else {}),
                **({"displacement_history": self.path} if self.path is not None else {})}


def _relax_level(system: PlasticSystem, relaxation: Relaxation, material: MohrCoulomb, srf: float, fixed_values=None) -> Level:
    """Dynamic relaxation from the committed state with ``material`` under the full loads."""
    timer = Timer()
    with _progress.current().stage(f"SRF {srf:.4f}"):    # the relaxation's steps, labelled with the level
        path = relax(system, material, 1.0, relaxation, fixed_values)
    history = [[h["step"], h["max_displacement"]] for h in path.history]
    seconds = timer.elapsed()
    growth = path.growth()
    if path.at_rest or growth <= SETTLED_GROWTH:
        note = "" if path.at_rest else (f"not at rest (out-of-balance {path.residual:.1e}) but settled: the "
                                        f"displacement grew {100 * growth:.2g} % over the last quarter of the steps")
        return Level(srf, True, path.steps, 0, seconds, system.snapshot(), note, history)
    return Level(srf, False, path.steps, 0, seconds, system.snapshot(),
                 f"not at rest, still moving ({100 * growth:.2g} % over the last quarter)", history)


def _level(system: PlasticSystem, loading, material_at, load_at, srf_at: Callable[[float], float], fixed_values=None,
           recheck: bool = True, runaway: Callable[[float, np.ndarray], Level] | None = None, resolution: float = 0.0
           ) -> tuple[Level, Level | None]:
    """Run the path t = 0..1 from the committed state; returns the level at t = 1 (stable, or failed
    at the sub-step that did not converge) and, for a failed level whose sub-steps got part of the way, the
    stable level reached (the system is left there).

    ``runaway(srf, U)``, where given (the search's response criterion), judges every sub-step in equilibrium
    before the last: one it finds failed ends the level there, failed in equilibrium, and the sub-step before
    it, where there is one, is the stable level reached. The levels beyond a runaway are failed at least as
    much (the search would judge one at that SRF the same way: from the same stable level, by the same measure),
    and the sub-steps after it would spend the iterations of a mechanism: on the 1928-node slope the
    iterations and cut-backs past SRF 1.356 that the step 1.3 -> 1.4 tried were half the search's time."""
    timer = Timer()
    carried: list[tuple[float, tuple]] = []          # the last two converged sub-steps: (t, snapshot)

    def converged(t: float, U: np.ndarray) -> dict:
        carried[:] = [*carried[-1:], (t, system.snapshot())]
        return {}

    def stop(t: float, U: np.ndarray) -> str | None:
        level = runaway(srf_at(t), U)
        return None if level.stable else level.criterion

    with _progress.current().stage(f"SRF {srf_at(1.0):.4f}"):   # Newton's increments, labelled with the level
        path = system.run(loading, material_at, load_at, converged, fixed_values=fixed_values,
                          stop_on_failure=True, recheck=recheck, stop=None if runaway is None else stop,
                          resolution=resolution)
    seconds = timer.elapsed()
    if path.stopped is not None:
        t, state = carried[-1]
        failed = runaway(srf_at(t), state[0])
        failed.iterations, failed.cutbacks, failed.seconds, failed.state = (path.newton_iterations, path.cutbacks,
                                                                            seconds, state)
        if len(carried) < 2:
            return failed, None
        t, state = carried[0]
        return failed, Level(srf_at(t), True, 0, 0, 0.0, state, "reached by the sub-steps of the next level")
    if path.failed_at is None:
        return Level(srf_at(1.0), True, path.newton_iterations, path.cutbacks, seconds, system.snapshot()), None
    failed = Level(srf_at(path.failed_at), False, path.newton_iterations, path.cutbacks, seconds,
                   system.trial_state(material_at(path.failed_at), path.failed_trial), "non-convergence")
    reached = [h["load_factor"] for h in path.history if h["converged"]]
    if not reached:
        return failed, None
    return failed, Level(srf_at(reached[-1]), True, 0, 0, 0.0, system.snapshot(),
                         "reached by the cut-back sub-steps of the next level")


def gravity_level(system: PlasticSystem, loading: Loading, material: MohrCoulomb, srf: float,
                  relaxation: Relaxation | None = None) -> Level:
    """Loads ramped from zero on the reduced material (the first stage of a search; one sweep level);
    with ``relaxation``, applied at once and relaxed (the paper's way)."""
    m = reduced(material, srf)
    if relaxation is not None:
        return _relax_level(system, relaxation, m, srf)
    return _level(system, loading, lambda t: m, lambda t: t, lambda t: srf, recheck=False)[0]


def search(system: PlasticSystem, loading: Loading, material: MohrCoulomb, settings: StrengthReduction,
           progress: Callable[[Level], None] = lambda level: None,
           relaxation: Relaxation | None = None) -> tuple[list[Level], Level, Level]:
    """Bracket and bisect the factor of safety; returns (levels in order, last stable, first failed
    of the final bracket). The ``system`` (a :class:`~ctmrpim.solvers.plastic_system.PlasticSystem`) is left
    in the last stable state."""
    first = gravity_level(system, loading, material, settings.start, relaxation)
    progress(first)
    levels = [first]
    if not first.stable:
        raise ProblemError(f"the body fails under its loads already at SRF = {settings.start:g} (the gravity "
                           "stage does not converge); lower strength-reduction.start", key="strength-reduction.start")
    stable, failed = first, None
    reference = max(first.max_displacement, 1e-300)
    fixed_values = system.U[system.fixed].copy()
    level_loading = replace(loading, steps=settings.steps)
    while failed is None or failed.srf - stable.srf > settings.width * (1 + 1e-9):
        target = stable.srf + settings.step if failed is None else 0.5 * (stable.srf + failed.srf)
        if target > settings.max_srf:
            raise ProblemError(f"no failure up to SRF = {settings.max_srf:g}; raise strength-reduction.max_srf",
                               key="strength-reduction.max_srf")
        system.restore(stable.state)
        s0 = stable.srf

        def runaway(srf: float, U: np.ndarray, below: Level = stable) -> Level:
            level = Level(srf, True, 0, 0, 0.0, (U,))
            _judge(below, level, reference, settings.limit_growth)
            return level

        srf_at = lambda t, s0=s0, s1=target: s0 + t * (s1 - s0)   # noqa: E731
        if relaxation is not None:     # the strength reduced at once, relaxed from the stable state
            level, reached = _relax_level(system, relaxation, reduced(material, target), target, fixed_values), None
        else:
            level, reached = _level(system, level_loading, lambda t: reduced(material, srf_at(t)), lambda t: 1.0,
                                    srf_at, fixed_values, runaway=runaway if settings.limit_growth > 0 else None,
                                    resolution=settings.width / (target - s0))
        if reached is not None:   # the cut-back sub-steps converged part of the way: stable there
            _judge(stable, reached, reference, settings.limit_growth)
            progress(reached)
            levels.append(reached)
            if reached.stable:
                stable = reached
            else:                 # it ran away already: the level beyond is failed at least as much
                reached.iterations, reached.cutbacks, reached.seconds = level.iterations, level.cutbacks, level.seconds
                failed = reached
                continue
        if level.stable:
            _judge(stable, level, reference, settings.limit_growth)
        progress(level)
        levels.append(level)
        if level.stable:
            stable = level
        else:
            failed = level
    system.restore(stable.state)
    return levels, stable, failed


def _judge(stable: Level, level: Level, reference: float, limit: float) -> None:
    """Mark ``level``, in equilibrium, failed where the displacement ran away from ``stable``: the largest nodal
    displacement between them per relative SRF rise, in units of ``reference`` (the largest displacement at
    SRF = start), above ``limit`` (0: no response criterion)."""
    rise = (level.srf - stable.srf) / stable.srf
    if rise <= 0:
        return
    level.growth = max_displacement(level.state[0] - stable.state[0]) / rise / reference
    if limit > 0 and level.growth > limit:
        level.stable = False
        level.criterion = (f"displacement runaway ({level.growth:.3g} x the displacement at SRF = start per unit "
                           f"relative SRF rise, above {limit:g}; in equilibrium)")


def sweep(system: PlasticSystem, loading: Loading, material: MohrCoulomb, values: tuple[float, ...],
          progress: Callable[[Level], None] = lambda level: None, relaxation: Relaxation | None = None
          ) -> list[Level]:
    """Each SRF of ``values`` on its own from ``system``'s committed state (a
    :class:`~ctmrpim.solvers.plastic_system.PlasticSystem`), gravity at the reduced strength."""
    start = system.snapshot()
    levels = []
    for srf in values:
        system.restore(start)
        level = gravity_level(system, loading, material, srf, relaxation)
        progress(level)
        levels.append(level)
    return levels


def bracket(levels: list[Level]) -> tuple[float | None, float | None]:
    """(largest stable SRF below the smallest failed one, smallest failed SRF); None where absent."""
    failed = min((lv.srf for lv in levels if not lv.stable), default=None)
    stable = max((lv.srf for lv in levels if lv.stable and (failed is None or lv.srf < failed)), default=None)
    return stable, failed


def solve_strength_reduction(case: Case, system: PlasticSystem, out, base: Result,
                             progress: Callable[[Level], None] = lambda level: None) -> Result:
    """Run the ``[strength-reduction]`` of ``case`` on ``system`` (a
    :class:`ctmrpim.solvers.plastic_system.PlasticSystem` of any discretisation, reported through ``out``, a
    :class:`ctmrpim.solvers.plastic_analysis.PlasticOutput`; not imported: that module imports this one) and fill
    ``base`` with the last stable state, the levels in the history and the series, and the factor of safety as
    a bracket."""
    settings: StrengthReduction = case.strength_reduction
    material = case.problem.material
    relaxation = case.relaxation if settings.solver == "dynamic-relaxation" else None
    timer = Timer()
    if settings.values:
        levels = sweep(system, case.loading, material, settings.values, progress, relaxation)
    else:
        levels, _, _ = search(system, case.loading, material, settings, progress, relaxation)
    seconds = timer.elapsed()
    stable, failed = bracket(levels)
    series = []
    for lv in levels:
        U, stress, _, plastic = lv.state
        series.append({"time": lv.srf, "load_factor": 1.0, "u": out.displacement(U), **out.nodal_stress(stress),
                       "fields": {**out.plastic_field(plastic), "stable": np.full(len(base.points), float(lv.stable))}})
    last = next((lv for lv in reversed(levels) if lv.stable and lv.srf == stable), None)
    if last is not None:
        U, stress, _, plastic = last.state
        base.u = out.displacement(U)
        nodal = out.nodal_stress(stress)
        base.stress, base.stress_zz = nodal["stress"], nodal["stress_zz"]
        base.probes = out.probe_values(U, stress[:, :3])
        base.fields = out.plastic_field(plastic)
    base.history = [lv.record() for lv in levels]
    base.series = series
    decisive = next((lv for lv in levels if not lv.stable and lv.srf == failed), None)
    ordered = sorted(levels, key=lambda lv: lv.srf)
    base.outcome = {"factor_of_safety": {"stable": stable, "failed": failed, "criterion": CRITERION[settings.solver],
                                         "mode": "sweep" if settings.values else "search",
                                         "decided_by": None if decisive is None else decisive.criterion.split(" (")[0],
                                         "limit_growth": settings.limit_growth if settings.solver == "newton" else None},
                    "srf_displacement": {"srf": [lv.srf for lv in ordered],
                                         "max_displacement": [lv.max_displacement for lv in ordered],
                                         "stable": [lv.stable for lv in ordered]}}
    base.counts.update(levels=len(levels), newton_iterations=sum(lv.iterations for lv in levels),
                       cutbacks=sum(lv.cutbacks for lv in levels), **system.iteration_counts())
    base.timings = {**base.timings, "strength_reduction": seconds,
                    "total": base.timings.get("total", 0.0) + seconds}
    return base
