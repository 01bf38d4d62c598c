"""Load stepping with Newton-Raphson and reported cut-backs (Section 2.1.3), for any discretisation.

The meshfree total-Lagrangian solver and the scikit-fem reference share this driver; each passes
how to assemble (F_ext, F_int, K) at a trial state and how to solve K du = r with its constraints.

Each increment is solved by Newton-Raphson on F_ext - F_int with a residual and a displacement
criterion; the residual is judged against max(|F_ext|, |F_int|), so that reactions carry a load
driven only by prescribed displacements. Each increment after the first starts from the secant
predictor, the last converged increment's displacement scaled to the new load step: a bending beam
rotates, and the tangent predictor alone stretches it (the first residual then grows a hundredfold and
Newton needs 10-15 iterations per increment; with the secant predictor 3-5). An increment that does not converge (or inverts the
material) is halved and retried, and the history says so, never silently; after an easy increment
a cut-back step grows back towards 1/steps. When an increment cannot be cut back any further the solve
gives up with a :class:`~ctmrpim.errors.ConvergenceError` carrying the history so far (the CLI writes it
and exits with status 3), unless the caller asked for the failure as an answer (a limit load, a
strength-reduction level). Each iteration is shown by the progress reporter (:mod:`ctmrpim.progress`):
"increment 3/16 (load factor 0.1875), iteration 2, residual 1.2e-06 of the loads", the increments counted
as converged ones plus those the current step still needs (so cut-backs raise the total).

A limit load judged by the response (issue 19, item 2): ``judge(factor_a, U_a, factor_b, U_b)``, where given, reads the response of a converged increment from the
last carried state (a) to the new one (b) and returns why the body has failed there (a response criterion:
the footing's settlement running away) or None, with entries for the history (the settlement): a failed
verdict (``converged`` False in the history, ``equilibrium`` True) is treated as a non-converged increment
(cut back from the carried state, and past the cut-backs the failure), so the bracket [carried, failed]
closes on the criterion, not on the solver's patience. With a ``judge`` the bracket closes on the step's size,
not on the count of cut-backs: an increment fails for good when its step is at most 1 / steps halved
``max_cutbacks`` times (the resolution), and both sides of the bracket are read at that resolution: where
the last carried increment was longer than ``ROLLBACK`` such steps, its end may already lie past the
criterion (a long step's secant averages the steep and the flat part of the curve), so the path goes back
to its start (``restore(snapshot())`` of the state there) and takes it again in halves, the step never
growing back beyond them.

``recheck``: an increment still not converged when the cut-backs are spent is tried once more before its
non-convergence counts (then judged like any converged one); the history says so. With an iteration on a fixed
matrix, every increment it does not converge is first handed over to Newton on the consistent tangent from its last
iterate (up to ``NEWTON_ITERATIONS``; fewer where its residual keeps rising, ``HAND_OVER_RISES``) before it is
cut back: near a limit the fixed-matrix iteration gives up at
levels where Newton converges in 3-13 iterations (measured on the 1928-node slope: every one of its eight cut-backs
between SRF 1.325 and 1.36 was such a level), so without the hand-over the cut-backs, not the body, set where the
search's bracket closes, and the 100 iterations of each give-up were half the search's time. An iteration on a fixed
matrix (``recheck_assemble`` given: the elastic stiffness with Anderson mixing) is re-checked by Newton on the
consistent tangent, up to ``RECHECK_LIMIT`` x ``NEWTON_ITERATIONS`` iterations; Newton's own iteration with
``RECHECK_LIMIT`` x ``max_iterations``. Why not more of the same patience: the elastic-stiffness iteration
converges linearly at a rate that worsens as the cloud is refined and as the body nears collapse, and its
residual is not monotone, so where it gives up depends on how long it is allowed to go on (measured: the slope,
psi = 0, at h = 0.42 m, FE P2, failed at SRF 1.30 with the cap 100 re-checked at 200, at [1.3266, 1.3328] re-checked
at 800 and at [1.3344, 1.3406] with the cap 400), while Newton either converges in a few iterations or runs away
(the same slope by Newton throughout: [1.3361, 1.3377], the failed level's iterate diverging).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp

from ctmrpim import progress
from ctmrpim.errors import ConvergenceError, ProblemError
from ctmrpim.problem.settings import Loading

#: Newton has diverged when a later step exceeds this many times both the increment's first step and
#: the converged displacement: a mechanism (a failed slope, a footing past its limit load), not slow
#: convergence, so the increment is cut back at once instead of using up its iterations.
DIVERGENCE = 100.0
#: With a response criterion (``judge``): the last carried increment is at most this many of the smallest steps
#: long, else it is taken again in halves (see :func:`step_loads`).
ROLLBACK = 4
#: The re-check of a non-converged increment takes this many times ``max_iterations`` (see the module doc).
RECHECK_LIMIT = 8
#: Newton's iterations per increment that the re-check of an iteration on a fixed matrix counts as its
#: ``max_iterations`` (the benchmarks' cap for the consistent tangent: it converges in 3-10 where there is an
#: equilibrium, and runs away where there is none).
NEWTON_ITERATIONS = 15
#: A hand-over's Newton has left the basin of the equilibrium when its residual rises in this many successive
#: iterations after its second (its first step, from the fixed-matrix iterate, raises the residual 10-50 times on
#: its own: the plastic zones move); see :func:`_hand_over`.
HAND_OVER_RISES = 2


class Anderson:
    """Anderson acceleration (type II, Walker & Ni 2011) of x -> x + f(x), f = K^-1 r the step.

    With a fixed matrix (the elastic stiffness of a Mohr-Coulomb body, factorised once) the plain
    iteration converges linearly, and slowly where much of the body is plastic; mixing each step with
    the last m by least squares accelerates it (for a linear problem it is GMRES). Measured on the
    1928-node slope under gravity, 4 increments, tolerance 1e-4: plain 937 iterations with 7 cut-backs
    (20.9 s), depth 5: 393 iterations (9.3 s). With a matrix that changes every iteration (full Newton)
    the history restarts each time and the step is Newton's."""

    def __init__(self, depth: int) -> None:
        self.depth = depth
        self.x: list[np.ndarray] = []
        self.f: list[np.ndarray] = []
        self.K = None

    def step(self, x: np.ndarray, f: np.ndarray, K: sp.spmatrix) -> np.ndarray:
        """The increment (n_dofs,) to add to the iterate x (n_dofs,), from the plain step f = K^-1 r (n_dofs,)."""
        if self.depth == 0:
            return f
        if K is not self.K:
            self.x, self.f, self.K = [], [], K
        self.x.append(x.copy())
        self.f.append(f.copy())
        if len(self.x) > self.depth + 1:
            self.x.pop(0)
            self.f.pop(0)
        if len(self.x) == 1:
            return f
        dX = np.diff(np.array(self.x), axis=0).T
        dF = np.diff(np.array(self.f), axis=0).T
        gamma = np.linalg.lstsq(dF, f, rcond=None)[0]
        return f - (dX + dF) @ gamma


@dataclass
class LoadPath:
    """The outcome of :func:`step_loads`: the last converged dofs U (n_dofs,), one history entry per increment
    tried (load_factor, converged, iterations, and a note or the ``on_converged`` entries), the cut-backs and
    Newton iterations."""
    U: np.ndarray
    history: list[dict[str, Any]] = field(default_factory=list)
    cutbacks: int = 0
    newton_iterations: int = 0
    failed_at: float | None = None   # with ``stop_on_failure``: the load factor that did not converge
    failed_trial: np.ndarray | None = None   # and the last iterate there (the first attempt's if the re-check failed)
    stopped: str | None = None       # with ``stop``: why the path ended at its last converged increment


@dataclass
class _Walk:
    """Where :func:`step_loads` is on the path: the carried load factor and the next step, the last converged
    step (the secant predictor's), the longest step allowed, the carried level's predecessor (``before``: where
    a roll-back returns to) and the increments converged so far."""
    factor: float
    dfactor: float
    max_step: float
    last_step: np.ndarray | None = None
    last_dfactor: float = 0.0
    before: tuple | None = None
    converged: int = 0


def step_loads(n_dofs: int, loading: Loading, fixed: np.ndarray, fixed_values: np.ndarray,
               assemble: Callable[[np.ndarray, float], tuple[np.ndarray, np.ndarray, sp.spmatrix]],
               solve: Callable[[sp.spmatrix, np.ndarray], np.ndarray],
               on_converged: Callable[[float, np.ndarray], dict[str, Any]], U0: np.ndarray | None = None,
               stop_on_failure: bool = False, anderson: int = 0,
               judge: Callable[[float, np.ndarray, float, np.ndarray], tuple[str | None, dict]] | None = None,
               recheck: bool = False, snapshot: Callable[[], Any] | None = None,
               restore: Callable[[Any], None] | None = None,
               recheck_assemble: Callable[[np.ndarray, float], tuple[np.ndarray, np.ndarray, sp.spmatrix]] | None = None,
               stop: Callable[[float, np.ndarray], str | None] | None = None, resolution: float = 0.0) -> LoadPath:
    """Apply the load in increments of the load factor from 0 up to 1 (cut-backs, the response criterion
    ``judge`` with ``snapshot`` and ``restore``, the ``recheck`` and its ``recheck_assemble``: the module doc).

    ``assemble(U, factor)`` returns (F_ext, F_int, K) at the trial state (a ProblemError there, e.g. an inverted
    material, cuts the increment back); ``solve(K, r)`` du with du = 0 at the fixed dofs; ``on_converged(factor,
    U)`` the extra history entries of a converged increment (it may record the state). The path starts from ``U0``
    (default zero), the prescribed displacements going linearly from their values there to ``fixed_values``. With
    no cut-back left the solve raises a ConvergenceError with the history so far, or with ``stop_on_failure``
    returns the path so far with ``failed_at`` set. ``anderson = m > 0``: :class:`Anderson` mixing of depth m.
    ``stop(factor, U)``, where given, reads every converged increment before the last once it is carried and returns why the path
    ends there (the path is returned with ``stopped`` set, its last increment carried) or None. ``resolution`` > 0: an
    increment at most that long (in load factor) that does not converge is not cut back further: the caller needs the
    failure no closer than that (a strength-reduction level whose sub-step is already narrower than the search's
    ``width``); it is re-checked like one whose cut-backs are spent."""
    path = LoadPath(U=np.zeros(n_dofs) if U0 is None else U0.copy())
    start_values = path.U[fixed].copy()
    walk = _Walk(factor=0.0, dfactor=1.0 / loading.steps, max_step=1.0 / loading.steps)
    report = progress.current()
    min_step = 1.0 / loading.steps / 2 ** loading.max_cutbacks

    def resolved() -> bool:
        return walk.dfactor <= resolution * (1 + 1e-9)

    def exhausted() -> bool:
        if judge is None:
            return path.cutbacks >= loading.max_cutbacks or resolved()
        return walk.dfactor <= max(min_step, resolution) * (1 + 1e-9)

    def newton(target: float, cap: int, assemble: Callable = assemble, start: np.ndarray | None = None,
               rises: int = 0) -> tuple[np.ndarray, bool, int]:
        if start is None:
            start = path.U.copy()
            if walk.last_step is not None:
                start += (target - walk.factor) / walk.last_dfactor * walk.last_step
            start[fixed] = start_values + target * (fixed_values - start_values)
        status = lambda it, r: report.status(_iteration_status(   # noqa: E731
            walk.converged, walk.factor, walk.dfactor, target, it, r, path.cutbacks))
        return _newton(path, start, target, cap, fixed, loading.tolerance, assemble, solve, anderson, status, rises)

    while walk.factor < 1.0 - 1e-12:
        target = min(1.0, walk.factor + walk.dfactor)
        trial, converged, it = newton(target, loading.max_iterations)
        verdict, note, judged = None, "", {}
        if not converged and recheck and exhausted():
            trial, converged, it, note = _recheck(newton, target, trial, loading.max_iterations,
                                                  assemble, recheck_assemble)
        elif not converged and recheck and recheck_assemble is not None:
            trial, converged, it, note = _hand_over(newton, target, trial, recheck_assemble)
        if converged and judge is not None:
            verdict, judged = judge(walk.factor, path.U, target, trial)
        if not converged or verdict is not None:
            reason = verdict if verdict is not None else (
                f"no convergence after {path.cutbacks} cut-back(s), the increment ({walk.dfactor:.4g}) within the "
                f"resolution asked for ({resolution:.4g})" if resolved() and path.cutbacks < loading.max_cutbacks
                else f"no convergence after {loading.max_cutbacks} cut-backs")
            entry = {"load_factor": target, "converged": False, "equilibrium": converged, "iterations": it}
            if (exhausted() and walk.before is not None
                    and walk.factor - walk.before[0] > ROLLBACK * min_step * (1 + 1e-9)):
                _roll_back(path, walk, restore, {**entry, **judged}, reason)
                continue
            if exhausted():
                path.history.append({**entry, "note": "; ".join(n for n in (reason, note) if n), **judged})
                report.status("")
                if stop_on_failure:
                    path.failed_at, path.failed_trial = target, trial
                    return path
                raise ConvergenceError(f"Newton did not converge at load factor {target:.4g} after "
                                       f"{loading.max_cutbacks} cut-backs; use more load steps", key="loading",
                                       history=path.history)
            path.cutbacks += 1
            walk.dfactor *= 0.5
            path.history.append({**entry, "note": (f"{verdict}: " if verdict is not None else "")
                                 + f"increment cut back to {walk.dfactor:.4g}", **judged})
            continue
        if judge is not None and snapshot is not None:   # where the path may come back to (see ROLLBACK)
            walk.before = (walk.factor, path.U, snapshot(), walk.last_step, walk.last_dfactor, len(path.history))
        walk.last_step, walk.last_dfactor = trial - path.U, target - walk.factor
        path.U, walk.factor = trial, target
        if it <= loading.max_iterations // 2:   # an easy increment: let a cut-back step grow back
            walk.dfactor = min(2.0 * walk.dfactor, walk.max_step)
        path.history.append({"load_factor": walk.factor, "converged": True, "iterations": it,
                             **({"note": note} if note else {}), **judged, **on_converged(walk.factor, path.U)})
        walk.converged += 1
        if stop is not None and walk.factor < 1.0 - 1e-12:
            path.stopped = stop(walk.factor, path.U)
            if path.stopped is not None:
                break
    report.status("")
    return path


def _recheck(newton: Callable, target: float, trial: np.ndarray, max_iterations: int, assemble: Callable,
             recheck_assemble: Callable | None) -> tuple[np.ndarray, bool, int, str]:
    """The re-check of an increment not converged with the cut-backs spent (the module doc): (the iterate,
    converged, iterations, the history's note). Newton starts from the fixed-matrix iteration's last iterate
    where there was one. Where the re-check fails too, the iterate kept is the first attempt's where it is finite:
    a Newton iterate running away from a mechanism reaches 1e11-1e13 m, a field that shows nothing."""
    cap = RECHECK_LIMIT * (max_iterations if recheck_assemble is None else NEWTON_ITERATIONS)
    finite = bool(np.all(np.isfinite(trial)))
    start = trial if recheck_assemble is not None and finite else None
    checked, converged, it = newton(target, cap, recheck_assemble or assemble, start)
    how = "" if recheck_assemble is None else "Newton on the consistent tangent, "
    if converged:
        return checked, True, it, f"converged only on the re-check ({how}{it} iterations)"
    return (trial if finite else checked), False, it, f"no convergence on the re-check ({how}{cap} iterations) either"


def _hand_over(newton: Callable, target: float, trial: np.ndarray, recheck_assemble: Callable
               ) -> tuple[np.ndarray, bool, int, str]:
    """An increment the fixed-matrix iteration did not converge while cut-backs are left: Newton on the consistent
    tangent from its last iterate, up to ``NEWTON_ITERATIONS``, before the increment is cut back (the module doc).
    (the iterate, converged, iterations, the history's note); the fixed-matrix iterate is kept where Newton fails.

    It gives up early where its residual rises ``HAND_OVER_RISES`` times in a row after the second iteration: it has
    left the basin. Measured on the 1928-node slope, the eight hand-overs between SRF 1.35 and 1.375: each of the
    six that failed rose twice in a row after its second iteration, then ran away (the divergence test) or ended at
    the cap with its residual 8-13 times its start; the two that converged (8 and 13 iterations) never rose twice in
    a row. With the early stop the search took 1673 iterations and 54 factorisations instead of 1710 and 91, for the
    same bracket [1.35137, 1.35176] (11.9 s against 14.1-15.6 s in one session). An increment it gives up is cut
    back, as at the cap; the re-check of an increment whose cut-backs are spent keeps its whole cap (:func:`_recheck`)."""
    if not np.all(np.isfinite(trial)):
        return trial, False, 0, ""
    checked, converged, it = newton(target, NEWTON_ITERATIONS, recheck_assemble, trial, rises=HAND_OVER_RISES)
    if converged:
        return checked, True, it, ("converged by Newton on the consistent tangent from the iteration's last "
                                   f"iterate ({it} iterations)")
    return trial, False, it, ""


def _roll_back(path: LoadPath, walk: _Walk, restore: Callable[[Any], None], entry: dict, reason: str) -> None:
    """The carried level was reached by a step longer than ``ROLLBACK`` of the smallest: go back to its start and
    take that step again in halves, never growing back beyond them (the module doc)."""
    a, U_a, state_a, walk.last_step, walk.last_dfactor, carried = walk.before
    path.history.append({**entry, "note": f"{reason}; the level below was reached by a step "
                         f"of {walk.factor - a:.4g}: taken again in halves from {a:.6g}"})
    path.history[carried].update(converged=False, note="not carried: its step was too long to read "
                                 "the curve at it; taken again in halves")
    restore(state_a)
    walk.max_step = walk.dfactor = 0.5 * (walk.factor - a)
    path.U, walk.factor, walk.before = U_a, a, None
    walk.converged -= 1


def _newton(path: LoadPath, trial: np.ndarray, target: float, cap: int, fixed: np.ndarray, tolerance: float,
            assemble: Callable, solve: Callable, anderson: int, status: Callable[[int, float], None],
            rises: int = 0) -> tuple[np.ndarray, bool, int]:
    """Newton's iterations (at most ``cap``) of one increment to load factor ``target`` from the predictor
    ``trial`` (n_dofs,); (the last iterate, converged, the iterations taken). Counts into ``path``. ``rises`` > 0:
    it also stops, not converged, once the relative residual has risen in that many successive iterations after
    the second."""
    converged, it, ref = False, 0, None
    previous, rising = math.inf, 0
    mixer = Anderson(anderson)
    for it in range(1, cap + 1):
        try:
            f_ext, f_int, K = assemble(trial, target)
        except ProblemError:
            break
        if ref is None:
            ref = max(np.linalg.norm(f_ext), 1e-30)
        residual = f_ext - f_int
        scale = max(ref, np.linalg.norm(f_int))   # reactions carry a displacement-driven load
        residual[fixed] = 0.0
        relative = float(np.linalg.norm(residual)) / scale
        status(it, relative)
        rising = rising + 1 if it > 2 and relative > previous else 0
        previous = relative
        if rises and rising >= rises:
            break                    # out of the basin: rising residuals (see _hand_over)
        du = solve(K, residual)
        if not np.all(np.isfinite(du)):
            raise ProblemError("the tangent stiffness is singular: the constraints do not stop every "
                               "rigid-body motion", key="constraint")
        trial = trial + mixer.step(trial, du, K)
        path.newton_iterations += 1
        if it == 1:
            first_step = np.linalg.norm(du)
        elif np.linalg.norm(du) > DIVERGENCE * max(first_step, np.linalg.norm(path.U)):
            break                    # a mechanism: Newton runs away; cut back without more iterations
        if (np.linalg.norm(residual) <= tolerance * scale
                and np.linalg.norm(du) <= tolerance * max(np.linalg.norm(trial), 1e-30)):
            converged = True
            break
    return trial, converged, it


def _iteration_status(done: int, factor: float, dfactor: float, target: float, iteration: int, residual: float,
                      cutbacks: int) -> str:
    """Where Newton is, for the progress reporter: the increment (of those converged, ``done``, plus the ones
    the step ``dfactor`` still needs from ``factor`` to 1), its ``target`` load factor, the iteration and the
    ``residual`` relative to the loads."""
    total = done + math.ceil((1.0 - factor) / dfactor - 1e-9)
    text = (f"increment {done + 1}/{total} (load factor {target:.4g}), iteration {iteration}, "
            f"residual {residual:.2e} of the loads")
    return text + (f", {cutbacks} cut-back(s) so far" if cutbacks else "")
