"""Momentum conservation of the explicit solver, and why explicit dynamics integrates with the paper's one-point
CTM (``"ctm"``) and not with the consistent scheme (``"ctm-vci"``; issue 17, item 3).

**Why "ctm" conserves momentum.** With linear-reproducing RPIM gradients, sum_I grad N_I = 0 and
sum_I x_I (x) grad N_I = F at every point, so the internal forces F_int = sum_p w_r P grad_r N of
:mod:`ctmrpim.solvers.explicit.frame` have no resultant and, F P^T = J sigma being symmetric, no torque.
Central differences then give p_{n+1/2} = p_{n-1/2} + h M g (h = (dt_{n-1} + dt_n) / 2), and the angular momentum about the centre of mass,
sum m (x_{n+1} - c_{n+1}) x (v_{n+1/2} - V_{n+1/2}) (positions after the step, half-step velocities), does not
change, to round-off; rebuilds and state transfers change neither x nor v. The elastic operator
K = G^T W C G of the stable time step is symmetric, so its eigenvalues are real and the LOBPCG estimate of
:mod:`ctmrpim.solvers.explicit.time_step` converges to omega_max^2 from below.

**Why "ctm-vci" does not.** Its corrected test gradients (:mod:`ctmrpim.discretisation.consistent_integration`)
do not sum to zero at a point: the internal force (Petrov-Galerkin, G~^T w P) has a resultant and a torque
wherever the stress is not linear (the quadratic correction integrates a linear stress exactly), and the
elastic operator G~^T W C G is not symmetric.

Measured here on the quick column cloud (16 x 9 nodes, :data:`CLOUD`), driving
:class:`~ctmrpim.solvers.explicit.run.ExplicitRun` step by step without walls (:func:`fly`):

- :data:`FREE_FLIGHT`: under gravity, launched with a translation, a spin and a squeeze that yields it
  (cohesion 2 kPa: the benchmark's cohesionless material, squeezed and spun, expands at zero stress after the
  rebound until a re-tracked area jumps and the run stops); the squeeze strains it enough for rebuilds and
  state transfers;
- :data:`SPIN`: no gravity, a rigid rotation of 20 rad/s, elastic (c = 1e9 Pa), rebuilt at 1 % strain (its
  centrifugal stretch and vibration; a rigid motion never triggers a rebuild). Faster spins keep their momenta
  too, but not their energy: at 50 rad/s (0.0105 rad per step) kinetic plus elastic energy grew by 35 % in
  10000 steps, by 2.7 % at half the step, an error of the time integration of a fast rotation (the column's
  lowest natural frequency is 186 rad/s: no resonance); at 20 rad/s, 0.11 %;
- each also with the internal force from the corrected test gradients (:class:`CorrectedForceRun`, a
  measurement only: the solver refuses ``ctm-vci`` in explicit analyses), at the plain run's smallest step;
- :func:`operators`: the resultant and torque of F_int with both gradients for the stress of the gravity stage
  (behind the gate), and the asymmetry and complex eigenvalues of both elastic operators.

The relative drifts are the largest over the steps of |p - p_0 - M g t| / sum_i m_i |v_i| (the size of the
momenta summed: |p| for a translation, M omega r for a spin) and |L - L_0| / |L_0|. :func:`measure` runs them
all (quick: :data:`QUICK_STEPS` steps, full: :data:`FULL_STEPS`) for the report's column-collapse section.
"""
from __future__ import annotations

import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ctmrpim import benchmarks
from ctmrpim.discretisation.configuration import Configuration
from ctmrpim.discretisation.consistent_integration import corrected_test_gradients
from ctmrpim.discretisation.gradient_operator import GradientOperator
from ctmrpim.materials.objective_stress import first_piola_c
from ctmrpim.solvers.explicit.run import ExplicitRun
from ctmrpim.solvers.explicit.time_step import checkerboard, omega_max

#: The column-collapse benchmark on the quick cloud of the tests (16 x 9 nodes); the benchmark sets alpha = 2.
CLOUD = ("nodes.grid=[16, 9]", "method.alpha=2.0")
QUICK_STEPS, FULL_STEPS = 1000, 10000
KEY = "explicit-conservation"


@dataclass(frozen=True)
class Flight:
    """A body without walls launched with v = translation + spin x (X - c) + squeeze (-(x - c_x), y - c_y), c the
    centre of mass; ``overrides`` of the column-collapse benchmark (material, rebuild criteria)."""

    name: str
    overrides: tuple[str, ...]
    translation: tuple[float, float]
    spin: float          # rad/s about the centre of mass
    squeeze: float       # 1/s: compresses x, stretches y

    def velocity(self, X: np.ndarray, mass: np.ndarray) -> np.ndarray:
        """(n, 2) the initial velocities of nodes ``X`` (n, 2) of masses ``mass`` (n,)."""
        r = X - mass @ X / mass.sum()
        return (np.asarray(self.translation) + self.spin * np.c_[-r[:, 1], r[:, 0]]
                + self.squeeze * r * np.array([-1.0, 1.0]))


FREE_FLIGHT = Flight("free flight", ("material.c=2e3", "explicit.rebuild_strain=0.1", "explicit.relay_strain=0.2"),
                     (1.0, 2.0), 5.0, 20.0)
SPIN = Flight("spin", ("material.c=1e9", "explicit.rebuild_strain=0.01", "problem.gravity=[0, 0]"),
              (0.0, 0.0), 20.0, 0.0)


class CorrectedForceRun(ExplicitRun):
    """An explicit run whose internal force uses ``ctm-vci``'s corrected test gradients, sum_p w_p P grad~N (the
    trial gradients, F, unchanged), on every frame it builds: a measurement of what the consistent scheme
    would do in explicit dynamics, not a solver path."""

    def frame_at(self, x: np.ndarray, free: np.ndarray, points: np.ndarray, w: np.ndarray,
                 loops: list[np.ndarray], triangles: np.ndarray) -> Configuration:
        frame = super().frame_at(x, free, points, w, loops, triangles)
        # the step hands over w P (the weights as they are now: points the step inverts get 0)
        frame.tested = corrected_operator(frame, self)
        return frame


def corrected_operator(frame: Configuration, run: ExplicitRun) -> GradientOperator:
    """The force product with the corrected test gradients of ``frame`` (the run's method and thickness)."""
    _, _, dx, dy = corrected_test_gradients(frame, run.case.method, run.thickness)
    return GradientOperator(dx, dy)


def momenta(mass: np.ndarray, x: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, float]:
    """Linear momentum (2,) and angular momentum about the centre of mass of nodes ``x`` (n, 2) moving at ``v``."""
    p = mass @ v
    total = mass.sum()
    r, u = x - mass @ x / total, v - p / total
    return p, float(mass @ (r[:, 0] * u[:, 1] - r[:, 1] * u[:, 0]))


def fly(flight: Flight, steps: int, corrected: bool = False, dt: float | None = None) -> dict:
    """``steps`` central-difference steps of ``flight`` (with the corrected test gradients' force if ``corrected``;
    a fixed step ``dt``, else the stable one): the largest relative drifts of linear and angular momentum
    (module docstring), the rebuilds, state transfers, largest plastic strain, turns of the spin and wall time."""
    fixed = [f"explicit.dt={float(dt)!r}"] if dt else []
    overrides = [*CLOUD, "explicit.initial=\"none\"", *flight.overrides, *fixed]
    case = benchmarks.load("column-collapse", overrides)
    case.problem.walls = []
    with tempfile.TemporaryDirectory() as tmp:
        run = (CorrectedForceRun if corrected else ExplicitRun)(case, Path(tmp), KEY)
        start = time.perf_counter()
        run.start()
        run.v[:] = flight.velocity(run.X, run.mass)
        impulse = run.mass.sum() * np.asarray(case.problem.gravity, float)
        p0, L0 = momenta(run.mass, run.x, run.v)
        dt_first = run.dt
        linear = angular = 0.0
        for _ in range(steps):
            run.advance([], 0.0)
            run.rebuild_if_needed()
            p, L = momenta(run.mass, run.x, run.v)
            size = float(run.mass @ np.linalg.norm(run.v, axis=1))
            # gravity's impulse acts from v_{-1/2} to v_{n+1/2}: t - (dt_n - dt_0) / 2 (h of the varying step)
            elapsed = run.t - 0.5 * (run.dt_previous - dt_first)
            linear = max(linear, float(np.linalg.norm(p - p0 - impulse * elapsed)) / size)
            angular = max(angular, abs(L - L0) / abs(L0))
        seconds = time.perf_counter() - start
    return {"case": flight.name, "integration": "ctm-vci (force only)" if corrected else "ctm", "steps": steps,
            "linear_drift": linear, "angular_drift": angular, "simulated_s": run.t, "dt_min_s": run.dt_range[0],
            "spin_rad_s": flight.spin, "turns": flight.spin * run.t / (2 * np.pi), "rebuilds": run.rebuilds, "transfers": run.transfers,
            "plastic_max": float(np.abs(run.plastic).max()), "free_particles": len(run.x) - len(run.frame.active),
            "time_s": seconds}


def operators() -> pd.DataFrame:
    """For "ctm" and "ctm-vci" on the quick column after the gravity stage (gate in place): the resultant
    |sum f| / sum |f_i| and the torque about the centre of mass |sum r x f| / sum |r| |f_i| of F_int for the
    stage's stress, and of the elastic operator A = M^-1/2 K M^-1/2 of the time step the asymmetry
    |A - A^T| / |A|, the largest |imaginary part| of its eigenvalues over the largest |eigenvalue|, and
    omega_max from its eigenvalues and from the solver's first estimate (:data:`~ctmrpim.solvers.explicit.time_step.ITERATIONS` steps from the
    checkerboard start)."""
    case = benchmarks.load("column-collapse", [*CLOUD, "explicit.duration=1e-9"])
    with tempfile.TemporaryDirectory() as tmp:
        run = ExplicitRun(case, Path(tmp), KEY)
        run.start()
        run.run(progress=False)
    frame = run.frame
    P = first_piola_c(run.stress, run.F)
    r = run.x - run.mass @ run.x / run.mass.sum()
    test = corrected_operator(frame, run)
    rows = []
    for name, force in (("ctm", frame.force), ("ctm-vci", lambda Q: test.force(Q * frame.w[:, None]))):
        f = force(P)
        size = np.linalg.norm(f, axis=1)
        K = _elastic_operator(run, force)
        A = _mass_scaled(K, run.mass)
        eig = np.linalg.eigvals(A)
        power, _ = omega_max(lambda d, K=K: (K @ d.ravel()).reshape(-1, 2), run.mass, checkerboard(run.x, run.d_c))
        rows.append({"integration": name, "resultant": float(np.linalg.norm(f.sum(axis=0)) / size.sum()),
                     "torque": float(abs(np.sum(r[:, 0] * f[:, 1] - r[:, 1] * f[:, 0]))
                                     / (np.linalg.norm(r, axis=1) @ size)),
                     "asymmetry": float(np.linalg.norm(A - A.T) / np.linalg.norm(A)),
                     "imaginary": float(np.abs(eig.imag).max() / np.abs(eig).max()),
                     "omega_max": float(np.sqrt(np.abs(eig).max())), "omega_estimate": power})
    return pd.DataFrame(rows)


def _elastic_operator(run: ExplicitRun, force) -> np.ndarray:
    """K (2n x 2n, interleaved dofs) of the run's small-strain elastic force on its frame with ``force`` (the
    product (m, 4) stresses -> (n, 2) forces), column by column."""
    frame, n = run.frame, len(run.x)

    def apply(d: np.ndarray) -> np.ndarray:
        L = frame.gradient(d)
        s = np.c_[L[:, 0] - 1.0, L[:, 3] - 1.0, L[:, 1] + L[:, 2]] @ run.D.T
        return force(np.c_[s[:, 0], s[:, 2], s[:, 2], s[:, 1]]).ravel()

    unit = np.eye(2 * n)
    return np.stack([apply(unit[j].reshape(n, 2)) for j in range(2 * n)], axis=1)


def _mass_scaled(K: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """M^-1/2 K M^-1/2 with the lumped nodal masses (n,)."""
    s = 1.0 / np.sqrt(np.repeat(mass, 2))
    return s[:, None] * K * s[None, :]


def measure(quick: bool = True) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The flights (free flight and spin, each with "ctm" and with the corrected force at the plain run's smallest
    step; quick: :data:`QUICK_STEPS` steps, full: :data:`FULL_STEPS`) and :func:`operators`."""
    steps = QUICK_STEPS if quick else FULL_STEPS
    rows = []
    for flight in (FREE_FLIGHT, SPIN):
        plain = fly(flight, steps)
        rows += [plain, fly(flight, steps, corrected=True, dt=plain["dt_min_s"])]
    return pd.DataFrame(rows), operators()
