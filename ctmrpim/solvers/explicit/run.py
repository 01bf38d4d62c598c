"""Explicit dynamic adaptive CTM-RPIM (Section 2.1.4, Eqs. 8-11; the soil collapse of Section 3.4).

    M a = F_ext - F_int + F_damp,       F_damp = -f |F_ext - F_int| sign(v)                  (Eqs. 9-11)

Central differences with the half-step velocity: v_{n+1/2} = v_{n-1/2} + dt M^-1 F_n, then contact with
the rigid walls (:mod:`ctmrpim.walls`) and fixed dofs, x_{n+1} = x_n + dt v_{n+1/2}. M is the lumped
mass of the initial cloud (:mod:`ctmrpim.lumped_mass`: positive, constant, so mass is conserved
exactly), F_ext the nodal weight m g, f = 0 by default (true dynamics).

**Viscosity** (``viscosity`` = beta, s; default 0): stiffness-proportional (Rayleigh) damping, a viscous
stress beta D d(eps)/dt at the points added to the Cauchy stress in F_int (not to the stress state that
yields), lagged by one step as explicit codes do; a mode of frequency omega gets the damping ratio
beta omega / 2, and the stable step becomes cfl 2 / omega_max (sqrt(1 + z^2) - z), z = beta omega_max / 2.
Why: the paper's model (rate-independent Mohr-Coulomb, no damping) lets the surface layer of the
collapsed column slide on long after the flow has stopped (measured on 496 nodes: still moving at 1 s,
the surface flattened to 11.5 deg against 14.6 deg measured); SPH models of granular flow, the method the
experiment was first compared with, carry an artificial viscosity, and a real granular flow's friction
grows with its shear rate (the mu(I) rheology), which a rate-independent model lacks. The value is a
setting, fitted for the benchmark (study ``column_collapse_viscosity``). The per-point work is in
:mod:`ctmrpim.explicit_point_update` (compiled); the internal force's products in
:mod:`ctmrpim.gradient_operator`.

**Configuration.** Boundary (alpha shape), CTM points and RPIM shape functions are built on the node
positions x_r of the last rebuild (the frame, a
:class:`~ctmrpim.discretisation.configuration.Configuration`). Between rebuilds the points move with the body:
the deformation gradient relative to x_r is F = I + grad_r (x - x_r), and

    F_int = sum_p w_r,p P_p grad_r N,      P = det F sigma F^-T,

the internal force on the current configuration written on x_r (exactly the force of the moved points,
without rebuilding anything). The Cauchy stress is updated at the points each step with the increment
f = F_{n+1} F_n^-1 (Hughes-Winget: sigma rotated by Q, then the Mohr-Coulomb return of the strain
increment in the rotated frame; :mod:`ctmrpim.objective_stress`, :mod:`ctmrpim.mohr_coulomb`).

**Rebuilds** (two levels). Once any point has been strained by more than ``rebuild_strain`` since the
last rebuild (largest |principal stretch - 1| of F: neighbouring nodes at d_c have then moved that
fraction of d_c relative to each other; a rigid motion never counts), the RPIM shape functions are
rebuilt on the current nodes at the points, which the body has carried with it (positions x_p + N (x -
x_r), weights w det F) and which keep their stress and plastic strain exactly. Once a point has been
strained by more than ``relay_strain`` since the points were laid, the boundary is re-tracked (alpha
shape) and new CTM points are laid over it (the paper's step (3)-(4)); the stress and plastic strain
are then L2-projected onto the nodes over the old points and evaluated at the new ones
(:mod:`ctmrpim.state_transfer`), projected stresses outside the yield surface are returned to it and
counted, and the elastic energy the projection changed is booked. Why two levels: laying new points
and transferring the state at every rebuild (measured on the 496-node collapse, 271 transfers)
smooths the stress of a cohesionless body that sits at yield almost everywhere, and the deposit kept
creeping after the flow had stopped; carried points keep the state and cost only the RPIM solve. A
re-tracked area that differs from the previous re-tracking's by more than ``area_jump`` stops the run
(the alpha shape opened or closed a gap: the body is nearly isochoric, so its alpha shape keeps its
area). The carried points' area (sum of w det F) is not the reference: where the front thins out, the
cohesionless material dilates at zero stress (the Mohr-Coulomb apex) and the nodes spread beyond
alpha, so the carried domain grows while the alpha shape leaves the dispersed grains out (measured on
2016 nodes at t = 0.33 s: carried 0.0243 m^2, re-tracked 0.0198, initial 0.0200); that difference is
reported (``tracked_area.dispersed``). The stable time step is recomputed at every rebuild
(:mod:`ctmrpim.critical_time_step`).

**Robustness at a thinning front**: a node that leaves the alpha shape becomes a free particle
(``detached = "free"``; gravity and the walls still act on it) or stops the run (``"stop"``); a
support holding fewer than ``method.min_support`` nodes is widened to that many; a point whose moment
matrix is singular, whose gradients exceed GRADIENT_LIMIT / d_c (it extrapolates), or which one step
turns inside out gets weight 0 (it integrates nothing; all counted in ``summary.json``). More than
INVERTED_LIMIT of the points inverted by one step is an unstable step: the run stops. Where the alpha
shape cannot be traced on the moved cloud (a pinch it cannot split; met once, on 2016 nodes at 0.18 s),
the run goes on with the carried points and tries again at the next rebuild (counted).

**Initial state** (``initial = "gravity"``): the column behind its gate is brought to rest under
gravity by the same scheme with local damping (``stage_damping``) and the ``gate`` walls in place,
until the out-of-balance force is below ``stage_tolerance`` of the weight; then velocities are set to
zero, t = 0 and the gates are removed. Why not a K0 stress state: with nu = 0.3 the elastic K0 =
nu / (1 - nu) = 0.43 lies below the active coefficient of phi = 19.8 deg (0.49), so that state is not
admissible for the cohesionless material; any other ratio (Jaky's 1 - sin phi = 0.66) is a guess, and a
prescribed field is not the discrete body's equilibrium (its nodal forces would not balance, and the
first steps would shake the column before the gate goes). The damped stage gives the discrete
equilibrium itself, yielded where the material must yield.

**Energy** (dynamic stage, from t = 0): the work of gravity, of the internal forces, of damping and of
the walls (their velocity corrections) is summed over the displacements dt (v_{n+1/2} + v_{n-1/2}) / 2,
for which central differences balance energy exactly (any sequence of dt): W_gravity + W_damping +
W_walls - W_internal = kinetic energy, to round-off (a check of the bookkeeping). Independently, at the
points: elastic energy, plastic dissipation sum w sigma : d eps_p, viscous dissipation and the energy
change of the transfers; W_internal against their sum measures the discretisation's error (the "material
balance").

**Long runs** (DESIGN.md): a VTU per ``save_every`` seconds and a ``.pvd`` index written as the run
goes; a progress bar; a checkpoint every ``checkpoint_every`` steps from which ``--resume`` continues
bit for bit (the frame is rebuilt from x_r; BLAS pinned to one thread); a run that diverges (non-finite
values, an inverted point, a node that left the body, a jump of the tracked area) stops with what,
where and when, and its last checkpoint is left as it was.
"""
from __future__ import annotations

import hashlib
import json
import shutil
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from ctmrpim.discretisation.alpha_shape import Boundary, alpha_shape
from ctmrpim.discretisation.boundary_conditions import constrained_dofs
from ctmrpim.discretisation.configuration import Configuration, build, lay_points, reference_cloud
from ctmrpim.discretisation.lumped_mass import lumped_mass
from ctmrpim.discretisation.state_transfer import NodalProjection
from ctmrpim.errors import ProblemError
from ctmrpim.io.checkpoint import NAME as CHECKPOINT
from ctmrpim.io.checkpoint import load_checkpoint, save_checkpoint
from ctmrpim.io.vtu import SeriesWriter
from ctmrpim.materials.mohr_coulomb import (
    ELASTIC,
    MohrCoulomb,
    elastic_strain,
    equivalent_plastic_strain,
    plastic_strain_increment,
)
from ctmrpim.materials.mohr_coulomb_kernel import PointUpdate, point_update
from ctmrpim.materials.objective_stress import (
    det_c,
    first_piola_c,
    hughes_winget_c,
    largest_strain_c,
    relative_c,
    rotate_c,
)
from ctmrpim.problem.case import Case
from ctmrpim.problem.model import Wall
from ctmrpim.problem.settings import Explicit
from ctmrpim.result import Result
from ctmrpim.solvers.explicit.contact import enforce_walls
from ctmrpim.solvers.explicit.time_step import (
    ITERATIONS,
    WARM_ITERATIONS,
    checkerboard,
    omega_max,
    stable_step,
    wave_speed_step,
)
from ctmrpim.timing import Timer

#: Largest |grad N| d_c of a point that integrates: regular clouds give 1.2 to 1.7, a thinned flow front
#: up to about 7; 40 to 60 was measured at points left beyond the nodes of a front (spurious stiffness
#: there cut the stable time step 30-fold).
GRADIENT_LIMIT = 10.0
#: More than this share of the integrating points inverted by one step: the step is unstable.
INVERTED_LIMIT = 0.01
#: History records per simulated second (at most; every step is cheaper to record than to skip here).
RECORDS_PER_SECOND = 500


class Diverged(ProblemError):
    """The run cannot go on; the message says what, where and when."""


@dataclass
class Energy:
    """Energy accounts of the dynamic stage (J per unit thickness times the thickness)."""

    gravity: float = 0.0       # work of gravity
    internal: float = 0.0      # work of the internal forces (stored + dissipated by the material)
    damping: float = 0.0       # work of the damping forces (<= 0)
    walls: float = 0.0         # work of the wall and support corrections (<= 0: dissipated by contact)
    plastic: float = 0.0       # plastic dissipation at the points
    transfer: float = 0.0      # elastic energy changed by the state transfers at rebuilds
    viscous: float = 0.0       # dissipated by the viscous stress (explicit.viscosity)
    elastic0: float = 0.0      # elastic energy at t = 0


class ExplicitRun:
    """One explicit run of a Case, writing its series and checkpoints into ``out``."""

    def __init__(self, case: Case, out: Path, key: str):
        problem = case.problem
        if not isinstance(problem.material, MohrCoulomb):
            raise ProblemError("explicit dynamics is implemented for model = \"mohr-coulomb\"", key="material.model")
        if case.method.boundary != "alpha":
            raise ProblemError("explicit dynamics integrates over the tracked boundary; set method.boundary = "
                               "\"alpha\"", key="method.boundary")
        self.case, self.out, self.key = case, Path(out), key
        self.settings: Explicit = case.explicit
        self.material = problem.material
        self.timer = Timer()
        cloud = reference_cloud(case, self.timer)
        self.X, self.lengths = cloud.nodes, cloud.lengths
        self.d_c = cloud.d_c
        n = len(self.X)
        self.thickness = problem.thickness
        self.mass = lumped_mass(self.X, cloud.boundary.triangles, self.material.density, self.thickness)
        self.weight = self.mass[:, None] * np.asarray(problem.gravity, float)[None, :]
        boundary_nodes = np.unique(np.concatenate(cloud.boundary.loops))
        tol = self.lengths.match_tolerance
        self.movable = np.ones((n, 2), bool)
        if problem.constraints:
            dofs, values = constrained_dofs(problem, self.X, boundary_nodes, tol)
            if np.any(values != 0):
                raise ProblemError("explicit dynamics holds constrained dofs still: every constraint value must be 0 "
                                   "(moving supports are not implemented)", key="constraint")
            self.movable.ravel()[dofs] = False
        self.walls: list[Wall] = list(problem.walls)
        for wall in self.walls:
            if np.any(wall.gap(self.X) < -tol):
                i = int(np.argmin(wall.gap(self.X)))
                raise ProblemError(f"node #{i} at ({self.X[i, 0]:g}, {self.X[i, 1]:g}) starts behind wall "
                                   f"{wall.name!r}", key="wall")
        self.D = self.material.D("strain")
        if self.material.tension is not None and self.settings.viscosity:
            raise ProblemError("explicit.viscosity with a tension cut-off (material.tension) is not implemented",
                               key="explicit.viscosity")
        self.dropped_points = 0
        self.timer.lap("set_up")

    # -- configuration -------------------------------------------------------------------------------
    def lay_frame(self, x: np.ndarray, free: np.ndarray) -> Configuration:
        """Boundary and new CTM points on positions x of the body's nodes (``free`` marks the others), and
        RPIM there. A node outside the alpha shape has left the body: with ``detached = "stop"`` the run
        stops naming it; with ``"free"`` it becomes a free particle for good (gravity and the walls move
        it, it keeps its mass, no stress): a grain that left the flow does not rejoin it, so it can never
        land on top of a node of the body (two nodes at one place make the RPIM moment matrix singular)."""
        body = np.flatnonzero(~free)
        sub = alpha_shape(x[body], self.lengths.alpha, self.d_c)
        detached = body[sub.detached]
        if len(detached) and self.settings.detached == "stop":
            i = int(detached[0])
            raise Diverged(f"{len(detached)} node(s) left the body (outside the alpha shape), e.g. node #{i} "
                           f"at ({x[i, 0]:.5g}, {x[i, 1]:.5g}): it has left the domain of influence; "
                           "increase method.alpha or set explicit.detached = \"free\"", key="method.alpha")
        free = free.copy()
        free[detached] = True
        loops = [body[lp] for lp in sub.loops]
        quad, w = lay_points([x[lp] for lp in loops], self.lengths, self.thickness)
        return self.frame_at(x, free, quad.points, w, loops)

    def frame_at(self, x: np.ndarray, free: np.ndarray, points: np.ndarray, w: np.ndarray,
                 loops: list[np.ndarray]) -> Configuration:
        """RPIM of the body's nodes at positions x (``free`` marks the others) at ``points`` with weights
        ``w``; ``loops`` the boundary (node indices). A point whose moment matrix is singular, or whose
        shape-function gradients exceed GRADIENT_LIMIT / d_c (it extrapolates from a support on one side,
        where the nodes around it have left the body), gets weight 0: it integrates nothing (counted)."""
        boundary = Boundary(points=x, loops=loops, triangles=np.zeros((0, 3), int), detached=np.flatnonzero(free))
        frame = build(x.copy(), boundary, points.copy(), w.copy(), self.lengths, active=np.flatnonzero(~free),
                      min_nodes=self.case.method.min_support, drop_singular=True)
        dx, dy = frame.sf.dNdx, frame.sf.dNdy
        size = np.sqrt(np.asarray(dx.multiply(dx).max(axis=1).todense()).ravel()
                       + np.asarray(dy.multiply(dy).max(axis=1).todense()).ravel()) * self.d_c
        dropped = np.union1d(frame.sf.dropped, np.flatnonzero(size > GRADIENT_LIMIT))
        frame.w[dropped] = 0.0
        self.dropped_points += len(dropped)
        return frame

    def _stiffness(self, frame: Configuration):
        """d (n, 2) -> elastic small-strain force K d on the frame (for the time step)."""
        def apply(d: np.ndarray) -> np.ndarray:
            L = frame.gradient(d)
            eps = np.c_[L[:, 0] - 1.0, L[:, 3] - 1.0, L[:, 1] + L[:, 2]]
            s = eps @ self.D.T
            return frame.force(np.c_[s[:, 0], s[:, 2], s[:, 2], s[:, 1]])
        return apply

    def _time_step(self) -> None:
        s = self.settings
        first = not np.isfinite(self.dt_range[0])
        omega, self.mode = omega_max(self._stiffness(self.frame), self.mass, self.mode, self.movable,
                                     ITERATIONS if first else WARM_ITERATIONS)
        self.omega = omega
        self.dt = float(s.dt) if s.dt != "cfl" else stable_step(omega, s.cfl, s.viscosity)
        self.dt_range = [min(self.dt_range[0], self.dt), max(self.dt_range[1], self.dt)]

    # -- the state -------------------------------------------------------------------------------------
    def start(self) -> None:
        n = len(self.X)
        self.x, self.v = self.X.copy(), np.zeros((n, 2))
        self.frame = self.lay_frame(self.x, np.zeros(n, bool))
        m = len(self.frame.w)
        self.stress, self.plastic, self.viscous = np.zeros((m, 4)), np.zeros((m, 4)), np.zeros((m, 4))
        self.F = np.tile(IDENTITY, (m, 1))
        self.laid = np.tile(IDENTITY, (m, 1))
        self.mode = checkerboard(self.X, self.d_c)
        self.dt_range = [np.inf, 0.0]
        self._time_step()
        self.dt_wave = wave_speed_step(_smallest_spacing(self.X), self.material.E, self.material.nu,
                                       self.material.density)
        self.stage = "gravity" if self.settings.initial == "gravity" else "dynamic"
        self.t, self.step, self.stage_steps = 0.0, 0, 0
        self.rebuilds, self.transfers, self.returned, self.areas, self.free_max = 0, 0, 0, [self.frame.boundary.area], 0
        self.area_changes: list[float] = []
        self.relay_failures, self.relay_failure = 0, ""
        self.energy = Energy()
        self.ke_peak, self.at_rest, self.stage_residual = 0.0, False, np.inf
        self.history: list[dict[str, Any]] = []
        self.series = SeriesWriter(self.out)
        self.next_save, self.next_record = 0.0, 0.0
        self.timer.lap("set_up")

    def _arrays(self) -> dict[str, np.ndarray]:
        fr = self.frame
        return {"x": self.x, "v": self.v, "frame_x": fr.x, "frame_free": fr.free,
                "frame_points": fr.points, "frame_w": fr.w, "frame_loops": np.concatenate(fr.boundary.loops),
                "frame_loop_sizes": [len(lp) for lp in fr.boundary.loops], "laid": self.laid, "stress": self.stress,
                "plastic": self.plastic, "viscous": self.viscous, "F": self.F, "mode": self.mode}

    def _meta(self) -> dict[str, Any]:
        return {"stage": self.stage, "t": self.t, "step": self.step, "stage_steps": self.stage_steps,
                "dt": self.dt, "omega": self.omega, "dt_range": self.dt_range, "dt_wave": self.dt_wave,
                "rebuilds": self.rebuilds, "transfers": self.transfers, "returned": self.returned, "areas": self.areas,
                "area_changes": self.area_changes,
                "free_max": self.free_max, "relay_failures": self.relay_failures,
                "relay_failure": self.relay_failure, "dropped_points": self.dropped_points,
                "energy": asdict(self.energy), "ke_peak": self.ke_peak, "stage_residual": self.stage_residual,
                "history": self.history, "series": self.series.entries, "next_save": self.next_save,
                "next_record": self.next_record}

    def checkpoint(self) -> None:
        save_checkpoint(self.out, self.key, self._meta(), self._arrays())

    def resume(self) -> None:
        meta, a = load_checkpoint(self.out, self.key)
        self.x, self.v = a["x"], a["v"]
        loops = np.split(a["frame_loops"], np.cumsum(a["frame_loop_sizes"])[:-1])
        self.frame = self.frame_at(a["frame_x"], a["frame_free"], a["frame_points"], a["frame_w"], loops)
        self.stress, self.plastic, self.F, self.mode = a["stress"], a["plastic"], a["F"], a["mode"]
        self.viscous = a["viscous"]
        self.laid = a["laid"]
        for k in ("stage", "t", "step", "stage_steps", "dt", "omega", "dt_range", "dt_wave", "rebuilds", "transfers",
                  "returned", "areas", "area_changes", "free_max", "relay_failures", "relay_failure",
                  "dropped_points", "ke_peak", "stage_residual",
                  "history", "next_save", "next_record"):
            setattr(self, k, meta[k])
        self.energy = Energy(**meta["energy"])
        self.at_rest = False
        self.series = SeriesWriter(self.out, meta["series"])
        self.timer.lap("set_up")

    # -- one step ------------------------------------------------------------------------------------
    def advance(self, walls: list[Wall], damping: float) -> None:
        """One central-difference step from (x_n, v_{n-1/2}, stress_n) to (x_{n+1}, v_{n+1/2}, stress_{n+1})."""
        fr, dt, F = self.frame, self.dt, self.F
        f_int = fr.force(first_piola_c(self.stress + self.viscous if self.settings.viscosity else self.stress, F))
        f = self.weight - f_int
        f_damp = -damping * np.abs(f) * np.sign(self.v) if damping else 0.0
        dv = dt * (f + f_damp) / self.mass[:, None]
        v = np.where(self.movable, self.v + dv, 0.0)
        v = enforce_walls(walls, self.x, v, dt)
        if not np.isfinite(v).all():
            i = int(np.flatnonzero(~np.isfinite(v).all(axis=1))[0])
            raise Diverged(f"non-finite velocity at node #{i} ({self.x[i, 0]:.5g}, {self.x[i, 1]:.5g}) at step "
                           f"{self.step}, t = {self.t:.6g} s")
        dx = dt * v
        if self.stage == "gravity":
            self.stage_residual = self._out_of_balance(f, walls)
        else:
            mid = 0.5 * dt * (v + self.v)       # dt (v_{n+1/2} + v_{n-1/2}) / 2: exact for any dt sequence
            e = self.energy
            e.gravity += float(np.sum(self.weight * mid))
            e.internal += float(np.sum(f_int * mid))
            if damping:
                e.damping += float(np.sum(f_damp * mid))
            e.walls += float(np.sum(self.mass[:, None] * (v - self.v - dv) * 0.5 * (v + self.v)))
        self.timer.lap("forces")
        x = self.x + dx
        F_new = fr.gradient(x - fr.x)
        f_inc = relative_c(F_new, F)
        J = det_c(f_inc)
        inverted = ~(J > 0) & (fr.w > 0)
        if inverted.any():
            # a point the step turns inside out: a few at a ragged front are dropped like the points
            # without shape functions (weight 0, no stress, counted); many at once is an unstable step
            if inverted.sum() > INVERTED_LIMIT * np.count_nonzero(fr.w):
                i = int(np.argmin(np.where(inverted, np.where(np.isfinite(J), J, -np.inf), np.inf)))
                p = fr.moved_points(x)[i]
                raise Diverged(f"the step inverts the material at {int(inverted.sum())} integration points (det f = "
                               f"{J[i]:.3g} at #{i} near ({p[0]:.5g}, {p[1]:.5g})) at step {self.step}, t = "
                               f"{self.t:.6g} s; use a smaller explicit.dt or explicit.cfl")
            fr.w[inverted] = 0.0
            self.dropped_points += int(inverted.sum())
        dead = ~(fr.w > 0)
        if dead.any():
            f_inc[dead], F_new[dead] = IDENTITY, IDENTITY
        w = fr.w * det_c(F_new)
        if self.material.tension is None:
            upd = point_update(self.material, f_inc, self.stress, self.plastic, dead, w, self.viscous,
                               self.settings.viscosity / dt)
        else:
            upd = self._point_update_numpy(f_inc, dead, w)
        if self.stage == "dynamic":
            self.energy.plastic += upd.dissipation
            self.energy.viscous += upd.viscous_work
        self.timer.lap("material")
        self.x, self.v, self.F = x, v, F_new
        self.stress, self.plastic, self.viscous = upd.stress, upd.plastic, upd.viscous
        self.t += dt
        self.step += 1

    def _point_update_numpy(self, f_inc: np.ndarray, dead: np.ndarray, w: np.ndarray) -> PointUpdate:
        """:func:`ctmrpim.explicit_point_update.point_update` in numpy forms, for the tension cut-off
        (no viscosity: refused with a tension cut-off)."""
        strain, c, s = hughes_winget_c(f_inc)
        rotated = rotate_c(self.stress, c, s)
        plastic = rotate_c(self.plastic, c, s)
        stress, region = self.material.update(rotated, strain)
        dp = plastic_strain_increment(self.material, strain, stress - rotated)
        stress[dead], plastic[dead], dp[dead] = 0.0, 0.0, 0.0
        return PointUpdate(stress, plastic + dp, region, float(w @ _contract(0.5 * (rotated + stress), dp)),
                           np.zeros_like(stress), 0.0)

    def _out_of_balance(self, f: np.ndarray, walls: list[Wall]) -> float:
        """|F_ext - F_int| over the weight, without what supports and walls in contact take."""
        r = np.where(self.movable, f, 0.0)
        for wall in walls:
            n = np.asarray(wall.normal)
            pressed = (wall.gap(self.x) <= 1e-9 * self.d_c) & (r @ n < 0)
            rn = r[pressed] @ n
            r[pressed] = wall.slip(r[pressed] - rn[:, None] * n, rn)   # the wall takes the normal part
        return float(np.linalg.norm(r) / np.linalg.norm(self.weight))

    # -- rebuild ---------------------------------------------------------------------------------------
    def rebuild_if_needed(self) -> bool:
        """Rebuild once a point has been strained by more than ``rebuild_strain`` since the last rebuild:
        the RPIM shape functions anew on the current nodes at the points carried with the body (their
        state kept as it is); once a point has been strained by more than ``relay_strain`` since the
        points were laid, the boundary is re-tracked and new CTM points laid, the state transferred."""
        s = self.settings
        if largest_strain_c(self.F) <= s.rebuild_strain:
            return False
        old, F = self.frame, self.F
        w_now = old.w * det_c(F)
        self.laid = _compose(F, self.laid)
        relay = largest_strain_c(self.laid) > s.relay_strain
        when = f"step {self.step}, t = {self.t:.6g} s"
        new = None
        if relay:
            try:
                new = self.lay_frame(self.x, old.free)
            except Diverged as exc:
                raise Diverged(f"{exc.message} (rebuild at {when})") from None
            except ProblemError as exc:
                # the alpha shape cannot be traced on this cloud (a pinch it cannot split): go on with
                # the carried points and try again at the next rebuild (counted, the first reason kept)
                self.relay_failures += 1
                self.relay_failure = self.relay_failure or f"{when}: {exc.message}"
                relay = False
        if new is None:
            try:
                new = self.frame_at(self.x, old.free, old.moved_points(self.x), w_now, old.boundary.loops)
            except ProblemError as exc:
                raise Diverged(f"the rebuild at {when} failed: {exc.message}") from None
        self.timer.lap("rebuild")
        if relay:
            area, carried, previous = new.boundary.area, float(w_now.sum()) / self.thickness, self.areas[-1]
            self.area_changes.append(area / carried - 1.0)
            if abs(area - previous) > s.area_jump * previous:
                raise Diverged(f"the re-tracked area {area:.6g} differs from the last re-tracking's {previous:.6g} "
                               f"({100 * (area / previous - 1):+.2f} %) at step {self.step}, t = {self.t:.6g} s: "
                               f"the alpha shape opened or closed a gap ({len(new.boundary.loops)} loop(s)); "
                               "change method.alpha, explicit.relay_strain or explicit.area_jump", key="method.alpha")
            elastic_before = float(w_now @ self._elastic_density(self.stress))
            nodal = _project(old, w_now, np.c_[self.stress, self.plastic, self.viscous])
            at_new = np.asarray(new.N @ nodal)
            stress, region = self.material.update(at_new[:, :4], np.zeros((len(at_new), 3)))
            self.returned += int(np.count_nonzero(region != ELASTIC))
            self.stress, self.plastic, self.viscous = stress, at_new[:, 4:8], at_new[:, 8:]
            self.viscous[~(new.w > 0)] = 0.0
            if self.stage == "dynamic":
                self.energy.transfer += float(new.w @ self._elastic_density(stress)) - elastic_before
            self.laid = np.tile(IDENTITY, (len(new.w), 1))
            self.transfers += 1
            self.areas.append(area)
            self.timer.lap("transfer")
        self.frame = new
        self.F = np.tile(IDENTITY, (len(new.w), 1))
        self.rebuilds += 1
        self.free_max = max(self.free_max, len(self.x) - len(new.active))
        self._time_step()
        self.timer.lap("time_step")
        return True

    # -- energy, output ------------------------------------------------------------------------------
    def _elastic_density(self, stress: np.ndarray) -> np.ndarray:
        """sigma : C sigma / 2 at the points."""
        return 0.5 * _contract(stress, elastic_strain(self.material, stress))

    def elastic_energy(self) -> float:
        return float((self.frame.w * det_c(self.F)) @ self._elastic_density(self.stress))

    def kinetic_energy(self) -> float:
        """0.5 sum m |v|^2 at the half step."""
        return 0.5 * float(self.mass @ np.einsum("nd,nd->n", self.v, self.v))

    def nodal_fields(self) -> dict[str, np.ndarray]:
        """Stress and equivalent plastic strain projected onto the nodes, with u and velocity."""
        fr = self.frame
        values = np.c_[self.stress, equivalent_plastic_strain(self.plastic)]
        nodal = _project(fr, fr.w * det_c(self.F), values)
        n = len(self.x)
        zeros = np.zeros((n, 1))
        u = self.x - self.X
        return {"u": np.c_[u, zeros], "velocity": np.c_[self.v, zeros], "displacement": np.linalg.norm(u, axis=1),
                "stress": nodal[:, :3], "szz": nodal[:, 3], "plastic_strain": nodal[:, 4]}

    def save(self) -> None:
        fields = self.nodal_fields()
        self.series.add(self.t, self.x, [("line", self.frame.boundary.edges)], fields)
        self.timer.lap("output")

    def record(self) -> None:
        ke = self.kinetic_energy()
        speed = np.linalg.norm(self.v, axis=1)
        e = self.energy
        self.history.append({"time": self.t, "step": self.step, "dt": self.dt, "kinetic": ke,
                             "elastic": self.elastic_energy(), "gravity_work": e.gravity, "internal_work": e.internal,
                             "plastic_dissipation": e.plastic, "wall_work": e.walls, "damping_work": e.damping,
                             "max_speed": float(speed.max()), "front": float(self.x[:, 0].max()),
                             "top": float(self.x[:, 1].max()), "rebuilds": self.rebuilds,
                             "free_particles": len(self.x) - len(self.frame.active)})

    # -- driver ----------------------------------------------------------------------------------------
    def run(self, progress: bool = True) -> None:
        s = self.settings
        bar = _bar(progress, s.duration)
        try:
            if self.stage == "gravity":
                bar.set_description("gravity stage")
                while self.stage_residual > s.stage_tolerance:
                    if self.stage_steps >= s.stage_steps:
                        raise Diverged(f"the gravity stage did not come to rest in {s.stage_steps} steps "
                                       f"(out-of-balance force {self.stage_residual:.2e} of the weight); raise "
                                       "explicit.stage_steps or explicit.stage_tolerance", key="explicit.stage_steps")
                    self.advance(self.walls, s.stage_damping)       # the gates stand
                    self.stage_steps += 1
                    self.rebuild_if_needed()
                    self._maybe_checkpoint()
                self._begin_dynamics()
            bar.set_description("collapse" if any(w.gate for w in self.walls) else "dynamics")
            walls = [w for w in self.walls if not w.gate]
            bar.update(self.t)
            while self.t < s.duration - 1e-12 * s.duration and not self.at_rest:
                self.advance(walls, s.damping)
                ke = self.kinetic_energy()
                self.ke_peak = max(self.ke_peak, ke)
                self.at_rest = self.ke_peak > 0 and ke < s.rest * self.ke_peak
                self.rebuild_if_needed()
                if self.t >= self.next_record or self.at_rest:
                    self.record()
                    self.next_record += 1.0 / RECORDS_PER_SECOND
                if self.t >= self.next_save - 1e-9 * self.dt:
                    self.save()
                    self.next_save += s.save_every
                self._maybe_checkpoint()
                bar.update(self.dt)
                if self.step % 50 == 0:
                    bar.set_postfix_str(f"step {self.step}, dt {self.dt:.2e} s, {self.rebuilds} rebuilds, "
                                        f"KE {ke:.3g} J")
            if not self.series.entries or self.series.entries[-1][0] < self.t:
                self.save()
        finally:
            bar.close()

    def _begin_dynamics(self) -> None:
        """End of the gravity stage: at rest, t = 0, gates removed, accounts opened."""
        self.v[:] = 0.0
        self.viscous[:] = 0.0            # at rest: no strain rate
        self.stage, self.t, self.step = "dynamic", 0.0, 0
        self.energy = Energy(elastic0=self.elastic_energy())
        self.record()
        self.save()
        self.next_save, self.next_record = self.settings.save_every, 1.0 / RECORDS_PER_SECOND
        self.checkpoint()

    def _maybe_checkpoint(self) -> None:
        every = self.settings.checkpoint_every
        count = self.step if self.stage == "dynamic" else self.stage_steps
        if every and count % every == 0:
            self.checkpoint()
            self.timer.lap("checkpoint")

    # -- result ----------------------------------------------------------------------------------------
    def result(self) -> Result:
        fields = self.nodal_fields()
        final = alpha_shape(self.x, self.lengths.alpha, self.d_c)      # the boundary of the final configuration
        e = self.energy
        ke, elastic = self.kinetic_energy(), self.elastic_energy()
        released = e.gravity
        balance = e.gravity + e.damping + e.walls - e.internal - ke
        material_error = e.internal - (elastic - e.elastic0 + e.plastic + e.viscous - e.transfer)
        timings = self.timer.total()
        steps = max(self.step + self.stage_steps, 1)
        dynamics = {
            "end_time": self.t, "steps": self.step, "stage_steps": self.stage_steps, "at_rest": self.at_rest,
            "dt": {"first": self.history[0]["dt"] if self.history else self.dt, "min": self.dt_range[0],
                   "max": self.dt_range[1], "wave_speed_bound": self.dt_wave, "setting": self.settings.dt},
            "rebuilds": self.rebuilds, "state_transfers": self.transfers, "returned_to_yield": self.returned,
            "re_tracking_failed": {"count": self.relay_failures, "first": self.relay_failure},
            "free_particles": {"final": len(self.x) - len(self.frame.active), "most": self.free_max,
                               "policy": self.settings.detached},
            "points_without_shape_functions": self.dropped_points,
            "energy": {"gravity_work": released, "kinetic": ke, "elastic": elastic, "elastic_initial": e.elastic0,
                       "plastic_dissipation": e.plastic, "wall_dissipation": -e.walls,
                       "damping_dissipation": -e.damping, "viscous_dissipation": e.viscous,
                       "transfer_change": e.transfer, "internal_work": e.internal,
                       "central_difference_balance": balance / max(abs(released), 1e-300),
                       "material_balance": material_error / max(abs(released), 1e-300)},
            "mass": {"total": float(self.mass.sum()), "min_nodal": float(self.mass.min())},
            "tracked_area": {"initial": float(self.areas[0]), "final": float(final.area),
                             "largest_retracking_change": float(np.abs(np.diff(self.areas) / self.areas[:-1]).max())
                             if len(self.areas) > 1 else 0.0,
                             "dispersed": float(-min(0.0, min(self.area_changes))) if self.area_changes else 0.0},
            "seconds_per_step": {k: v / steps for k, v in timings.items()
                                 if k in ("forces", "material", "rebuild", "transfer", "time_step", "output",
                                          "checkpoint", "total")},
        }
        n = len(self.X)
        return Result(
            method="ctm-rpim-explicit", points=self.X, u=self.x - self.X, stress=fields["stress"],
            cells=[("line", final.edges)], counts={"nodes": n, "integration_points": len(self.frame.w),
                                                   "steps": self.step, "rebuilds": self.rebuilds,
                                                   "boundary_loops": len(final.loops)},
            timings=timings, history=self.history,
            fields={"velocity": fields["velocity"], "plastic_strain": fields["plastic_strain"]},
            parameters={**self.case.resolved, "derived": {"d_c": self.d_c, "alpha": self.lengths.alpha,
                                                          "support_radius": self.lengths.support_radius}},
            defaults=self.case.defaults, outcome={"dynamics": dynamics})


IDENTITY = np.array([1.0, 0.0, 0.0, 1.0])


def _compose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(m, 4) products a b of gradients stored xx, xy, yx, yy."""
    return np.stack([a[:, 0] * b[:, 0] + a[:, 1] * b[:, 2], a[:, 0] * b[:, 1] + a[:, 1] * b[:, 3],
                     a[:, 2] * b[:, 0] + a[:, 3] * b[:, 2], a[:, 2] * b[:, 1] + a[:, 3] * b[:, 3]], axis=1)


def _project(frame: Configuration, w: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Nodal values (n, k) of point values (m, k): the L2 projection over the body nodes that some point
    of positive weight supports; the others (free particles, nodes left beside the dropped points of a
    thinned front, where the stress is about zero) get zero."""
    out = np.zeros((frame.N.shape[1], values.shape[1]))
    keep = frame.active[np.asarray(abs(frame.N[:, frame.active]).T @ w).ravel() > 0]
    out[keep] = NodalProjection(frame.N[:, keep], w)(values)
    return out


def _contract(s: np.ndarray, e: np.ndarray) -> np.ndarray:
    """s : e of (m, 4) tensors stored xx, yy, xy, zz."""
    return s[:, 0] * e[:, 0] + s[:, 1] * e[:, 1] + 2.0 * s[:, 2] * e[:, 2] + s[:, 3] * e[:, 3]


def _smallest_spacing(x: np.ndarray) -> float:
    d, _ = cKDTree(x).query(x, k=2)
    return float(d[:, 1].min())


def _bar(enabled: bool, total: float):
    from tqdm import tqdm
    return tqdm(total=total, disable=not enabled, unit="s", unit_scale=False, leave=False, mininterval=0.5,
                bar_format="{desc}: {n:.3f}/{total:.3f} s simulated |{bar}| {elapsed}<{remaining} {postfix}")


def input_key(case: Case) -> str:
    """Hash of the resolved input and the code version: a checkpoint resumes only the same run."""
    from ctmrpim.io.provenance import code_version
    text = json.dumps({"resolved": case.resolved, "version": code_version()}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def solve_explicit(case: Case, out: Path, resume: bool = False, progress: bool = False) -> Result:
    """Run the explicit dynamic analysis of ``case`` into the folder ``out`` (series, checkpoints);
    ``resume`` continues from the folder's checkpoint. BLAS is pinned to one thread, so that a resumed
    run repeats the uninterrupted one bit for bit."""
    from threadpoolctl import threadpool_limits

    out = Path(out)
    run = ExplicitRun(case, out, input_key(case))
    with threadpool_limits(1):
        if resume:
            run.resume()
        else:
            if (out / "series").is_dir():
                shutil.rmtree(out / "series")     # a fresh run: no stale states of an earlier one
            for name in (CHECKPOINT, "result.pvd"):
                (out / name).unlink(missing_ok=True)
            run.start()
        for name in ("summary.json", "result.vtu"):   # until this run ends, nothing looks complete
            (out / name).unlink(missing_ok=True)
        run.run(progress)
        return run.result()

