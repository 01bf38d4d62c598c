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
a cut-back step grows back towards 1/steps.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp

from .errors import ProblemError
from .problem_file import Loading


@dataclass
class LoadPath:
    U: np.ndarray
    history: list[dict[str, Any]] = field(default_factory=list)
    cutbacks: int = 0
    newton_iterations: int = 0


def step_loads(n_dofs: int, loading: Loading, fixed: np.ndarray, fixed_values: np.ndarray,
               assemble: Callable[[np.ndarray, float], tuple[np.ndarray, np.ndarray, sp.spmatrix]],
               solve: Callable[[sp.spmatrix, np.ndarray], np.ndarray],
               on_converged: Callable[[float, np.ndarray], dict[str, Any]]) -> LoadPath:
    """Apply the load in increments of the load factor up to 1.

    ``assemble(U, factor)`` returns (F_ext, F_int, K) at the trial state (a ProblemError there, e.g.
    an inverted material, cuts the increment back); ``solve(K, r)`` returns du with du = 0 at the
    fixed dofs; ``on_converged(factor, U)`` returns the extra history entries of a converged increment
    (probe values) and may record the state. Prescribed displacements are scaled by the load factor.
    """
    steps, tolerance = loading.steps, loading.tolerance
    path = LoadPath(U=np.zeros(n_dofs))
    factor, dfactor = 0.0, 1.0 / steps
    last_step, last_dfactor = None, 0.0
    while factor < 1.0 - 1e-12:
        target = min(1.0, factor + dfactor)
        trial, converged, it = path.U.copy(), False, 0
        if last_step is not None:
            trial += (target - factor) / last_dfactor * last_step
        trial[fixed] = target * fixed_values
        ref = None
        for it in range(1, loading.max_iterations + 1):
            try:
                f_ext, f_int, K = assemble(trial, target)
            except ProblemError:
                break
            if ref is None:
                ref = max(np.linalg.norm(f_ext), 1e-30)
            residual = f_ext - f_int
            scale = max(ref, np.linalg.norm(f_int))   # reactions carry a displacement-driven load
            residual[fixed] = 0.0
            du = solve(K, residual)
            if not np.all(np.isfinite(du)):
                raise ProblemError("the tangent stiffness is singular: the constraints do not stop every "
                                   "rigid-body motion", key="constraint")
            trial += du
            path.newton_iterations += 1
            if (np.linalg.norm(residual) <= tolerance * scale
                    and np.linalg.norm(du) <= tolerance * max(np.linalg.norm(trial), 1e-30)):
                converged = True
                break
        if not converged:
            if path.cutbacks >= loading.max_cutbacks:
                raise ProblemError(f"Newton did not converge at load factor {target:.4g} after "
                                   f"{loading.max_cutbacks} cut-backs; use more load steps", key="loading")
            path.cutbacks += 1
            dfactor *= 0.5
            path.history.append({"load_factor": target, "converged": False, "iterations": it,
                                 "note": f"increment cut back to {dfactor:.4g}"})
            continue
        last_step, last_dfactor = trial - path.U, target - factor
        path.U, factor = trial, target
        if it <= loading.max_iterations // 2:   # an easy increment: let a cut-back step grow back
            dfactor = min(2.0 * dfactor, 1.0 / steps)
        path.history.append({"load_factor": factor, "converged": True, "iterations": it,
                             **on_converged(factor, path.U)})
    return path
