"""Explicit dynamic adaptive CTM-RPIM (Section 2.1.4, Eqs. 8-11; the soil collapse of Section 3.4): the driver.

    M a = F_ext - F_int + F_damp,       F_damp = -f |F_ext - F_int| sign(v)                  (Eqs. 9-11)

integrated by central differences on a constant lumped mass, with rigid walls, an optional viscosity, the
points carried by the body between rebuilds, energy accounts and checkpoints. :class:`ExplicitRun` is one
run; each of its parts is a module of this package:

- :mod:`~ctmrpim.solvers.explicit.state`: what a run holds (declared there), its start, checkpoints, resume;
- :mod:`~ctmrpim.solvers.explicit.frame`: the configuration the points are built on (boundary, CTM points,
  RPIM), F_int written on it, the points dropped at a thinning front;
- :mod:`~ctmrpim.solvers.explicit.step`: one central-difference step (Eqs. 9-11), the viscosity;
- :mod:`~ctmrpim.solvers.explicit.nodal_update`, :mod:`~ctmrpim.solvers.explicit.point_pass`: the step's compiled
  passes over the nodes (update, walls, works) and over the points (gradient, stress update, internal force);
- :mod:`~ctmrpim.solvers.explicit.contact`: the rigid walls;
- :mod:`~ctmrpim.solvers.explicit.rebuild`: the two-level rebuilds and the state transfer;
- :mod:`~ctmrpim.solvers.explicit.time_step`: the stable time step;
- :mod:`~ctmrpim.solvers.explicit.energy`: the energy accounts and what the balances check;
- :mod:`~ctmrpim.solvers.explicit.output`: the VTU series and the history records;
- :mod:`~ctmrpim.solvers.explicit.errors`: :class:`~ctmrpim.solvers.explicit.errors.Diverged`.

Those that act on the run's state are mixins of :class:`ExplicitRun`, not functions handed the run: the
step, the rebuilds, the output and the checkpoints all read and write the same positions, stresses, frame,
counters and accounts, so one object holds them (declared in :class:`~ctmrpim.solvers.explicit.state.RunState`)
and each module adds the methods of its one job; what needs no state (the numpy point update, the
out-of-balance force, the projection onto the nodes, the energy densities, the time-step formulas) is a
plain function. Here: the set-up (the input's checks, the reference cloud, lumped mass, supports, walls),
the run loop (the gravity stage, then the dynamics), the result and :func:`solve_explicit`.

**Integration: the paper's one-point CTM only** (``method.integration = "ctm"``; docs/design.md, 'Explicit
dynamics'). The RPIM gradients reproduce linear fields, so at every point sum_I grad N_I = 0 and
sum_I x_I (x) grad N_I = F: F_int = sum_p w_r P grad_r N has no resultant and, F P^T = J sigma being symmetric,
no torque, and central differences conserve linear momentum (p_{n+1/2} = p_{n-1/2} + dt M g) and the angular
momentum sum m x_{n+1} x v_{n+1/2} (about the centre of mass under gravity) to round-off, through rebuilds and
state transfers, which change neither x nor v. Measured over 10000 steps on the quick column cloud
(tests/verification/test_explicit_momentum.py, ``studies/explicit_conservation.py``): a free flight under
gravity that yields, 2.0e-13 (linear) and 4.6e-15 (angular); an elastic spin, 5.0e-16 and 7.9e-16. The corrected
test gradients of ``ctm-vci`` do not sum to zero at a point: with them F_int of the gravity stage's stress has a
resultant of 1.6e-5 of sum |f_i| and a torque of 2.4e-5, the same flights drift by 1.3e-3 / 6.6e-2 and
1.5e-4 / 3.0e-4, and the elastic operator of the time step is no longer symmetric
(:mod:`~ctmrpim.solvers.explicit.time_step`); :mod:`ctmrpim.solvers.meshfree` refuses it here.

**Initial state** (``initial = "gravity"``): the column behind its gate is brought to rest under
gravity by the same scheme with local damping (``stage_damping``) and the ``gate`` walls in place,
until the out-of-balance force is below ``stage_tolerance`` of the weight; then velocities are set to
zero, t = 0 and the gates are removed. Why not a K0 stress state: with nu = 0.3 the elastic K0 =
nu / (1 - nu) = 0.43 lies below the active coefficient of phi = 19.8 deg (0.49), so that state is not
admissible for the cohesionless material; any other ratio (Jaky's 1 - sin phi = 0.66) is a guess, and a
prescribed field is not the discrete body's equilibrium (its nodal forces would not balance, and the
first steps would shake the column before the gate goes). The damped stage gives the discrete
equilibrium itself, yielded where the material must yield.

**Long runs** (docs/design.md, 'Explicit dynamics'): a VTU per ``save_every`` seconds and a ``.pvd`` index
written as the run goes; its progress (stage, simulated time, step, time step, rebuilds, kinetic energy) as
the status of the progress reporter (:mod:`ctmrpim.progress`: a live line on a terminal, a line every few
seconds in a log); a checkpoint every ``checkpoint_every`` steps from which ``--resume`` continues bit for
bit (the frame is rebuilt from x_r; BLAS pinned to one thread); a run that diverges (non-finite values, an
inverted point, a node that left the body, a jump of the tracked area) stops with what, where and when and
the history up to there (:class:`~ctmrpim.solvers.explicit.errors.Diverged`, a ConvergenceError), and its
last checkpoint is left as it was.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ctmrpim import progress as _progress
from ctmrpim.discretisation.alpha_shape import alpha_shape
from ctmrpim.discretisation.boundary_conditions import constrained_dofs
from ctmrpim.discretisation.configuration import reference_cloud
from ctmrpim.discretisation.lumped_mass import lumped_mass
from ctmrpim.errors import ProblemError
from ctmrpim.io.atomic import atomic_write_text
from ctmrpim.io.run_folder import SERIES, STEP, remove_outputs
from ctmrpim.io.vtu import pvd_text
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.problem.case import Case
from ctmrpim.problem.model import Wall
from ctmrpim.problem.settings import Explicit
from ctmrpim.result import Result
from ctmrpim.solvers.explicit.energy import Energy, StoredEnergy
from ctmrpim.solvers.explicit.errors import Diverged
from ctmrpim.solvers.explicit.frame import FrameBuilder
from ctmrpim.solvers.explicit.output import SeriesOutput
from ctmrpim.solvers.explicit.rebuild import Rebuilds
from ctmrpim.solvers.explicit.state import RunState, input_key
from ctmrpim.solvers.explicit.step import CentralDifference
from ctmrpim.solvers.explicit.time_step import TimeStepping
from ctmrpim.timing import Timer

#: History records per simulated second (at most; every step is cheaper to record than to skip here).
RECORDS_PER_SECOND = 500
#: The progress status is refreshed every this many steps (a status is cheap, but not free at every step).
STATUS_EVERY = 50


class ExplicitRun(RunState, FrameBuilder, TimeStepping, CentralDifference, Rebuilds, StoredEnergy, SeriesOutput):
    """One explicit run of a Case, writing its series and checkpoints into ``out``; ``key`` the checkpoints'
    :func:`~ctmrpim.solvers.explicit.state.input_key`. n nodes: ``X`` (n, 2) the reference cloud, ``mass``
    (n,) lumped, ``weight`` (n, 2) m g, ``movable`` (n, 2) the free dofs; the evolving state is
    :class:`~ctmrpim.solvers.explicit.state.RunState`'s."""

    def __init__(self, case: Case, out: Path, key: str) -> None:
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
        self.reference_triangles = cloud.boundary.triangles      # corners kept: carried while valid
        self.tracking = [0, 0]                                   # boundaries tracked: carried, alpha shape
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
        self.timer.lap("set_up", nodes=n)

    # -- driver ----------------------------------------------------------------------------------------
    def run(self, progress: bool = True) -> None:
        """Run from the present state: the gravity stage until at rest (if not over), then the dynamics
        until ``duration`` or at rest, saving, recording and checkpointing as set; ``progress``: report each
        :data:`STATUS_EVERY` steps to the progress reporter in force."""
        s = self.settings
        report = _progress.current() if progress else _progress.SILENT
        try:
            if self.stage == "gravity":
                report.status("gravity stage: starting")
                while self.stage_residual > s.stage_tolerance:
                    if self.stage_steps >= s.stage_steps:
                        raise Diverged(f"the gravity stage did not come to rest in {s.stage_steps} steps "
                                       f"(out-of-balance force {self.stage_residual:.2e} of the weight); raise "
                                       "explicit.stage_steps or explicit.stage_tolerance", key="explicit.stage_steps")
                    self.advance(self.walls, s.stage_damping)       # the gates stand
                    self.stage_steps += 1
                    self.rebuild_if_needed()
                    self._maybe_checkpoint()
                    if self.stage_steps % STATUS_EVERY == 0:
                        report.status(f"gravity stage: step {self.stage_steps}, out-of-balance force "
                                      f"{self.stage_residual:.2e} of the weight (to {s.stage_tolerance:g}), "
                                      f"{self.rebuilds} rebuilds")
                self._begin_dynamics()
            stage = "collapse" if any(w.gate for w in self.walls) else "dynamics"
            walls = [w for w in self.walls if not w.gate]
            report.status(f"{stage}: t = {self.t:.4f} of {s.duration:g} s simulated, step {self.step}")
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
                if self.step % STATUS_EVERY == 0:
                    report.status(f"{stage}: t = {self.t:.4f} of {s.duration:g} s simulated "
                                  f"({100 * self.t / s.duration:.0f} %), step {self.step}, dt {self.dt:.2e} s, "
                                  f"{self.rebuilds} rebuilds, kinetic energy {ke:.3g} J, {len(self.series.entries)} "
                                  "states saved")
            if not self.series.entries or self.series.entries[-1][0] < self.t:
                self.save()
        except Diverged as exc:     # the history up to here goes to summary.json beside the reason
            exc.history = list(self.history)
            raise
        finally:
            report.status("")

    def _begin_dynamics(self) -> None:
        """End of the gravity stage: at rest, t = 0, gates removed, accounts opened."""
        self.v[:] = 0.0
        self.viscous[:] = 0.0            # at rest: no strain rate
        self.force_of_F = None           # the force of the last step had the viscous stress in it
        self.stage, self.t, self.step = "dynamic", 0.0, 0
        self.dt_previous = self.dt       # at rest: v_{-1/2} = 0, the first step a full one as from start()
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
        """The run's :class:`~ctmrpim.result.Result`: the final displacements and nodal fields on the final
        boundary, the history, and the summary of the dynamics (time steps, rebuilds, energy balances, areas)."""
        fields = self.nodal_fields()
        final = alpha_shape(self.x, self.lengths.alpha, self.d_c)      # the boundary of the final configuration
        e = self.energy
        ke, elastic = self.kinetic_energy(), self.elastic_energy()
        released = e.gravity
        balance = e.gravity + e.damping + e.walls - e.internal - ke
        material_error = e.internal - e.rebuild - (elastic - e.elastic0 + e.plastic + e.viscous - e.transfer)
        timings = self.timer.total()
        steps = max(self.step + self.stage_steps, 1)
        dynamics = {
            "end_time": self.t, "steps": self.step, "stage_steps": self.stage_steps, "at_rest": self.at_rest,
            "dt": {"first": self.history[0]["dt"] if self.history else self.dt, "min": self.dt_range[0],
                   "max": self.dt_range[1], "wave_speed_bound": self.dt_wave, "setting": self.settings.dt},
            "rebuilds": self.rebuilds, "state_transfers": self.transfers, "returned_to_yield": self.returned,
            "transfer_clipped": self.clipped,
            "boundaries_tracked": {"carried": self.tracking[0], "alpha_shape": self.tracking[1]},
            "re_tracking_failed": {"count": self.relay_failures, "first": self.relay_failure},
            "free_particles": {"final": len(self.x) - len(self.frame.active), "most": self.free_max,
                               "policy": self.settings.detached},
            "points_without_shape_functions": self.dropped_points,
            "energy": {"gravity_work": released, "kinetic": ke, "elastic": elastic, "elastic_initial": e.elastic0,
                       "plastic_dissipation": e.plastic, "wall_dissipation": -e.walls,
                       "damping_dissipation": -e.damping, "viscous_dissipation": e.viscous,
                       "transfer_change": e.transfer, "rebuild_force_change": e.rebuild, "internal_work": e.internal,
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
            stress_zz=fields["szz"], cells=[("line", final.edges), ("triangle", final.triangles)],
            counts={"nodes": n, "integration_points": len(self.frame.w), "steps": self.step, "rebuilds": self.rebuilds,
                    "boundary_loops": len(final.loops)},
            timings=timings, history=self.history,
            fields={"velocity": fields["velocity"], "plastic_strain": fields["plastic_strain"]},
            parameters={**self.case.resolved, "derived": {"d_c": self.d_c, "alpha": self.lengths.alpha,
                                                          "support_radius": self.lengths.support_radius}},
            defaults=self.case.defaults, outcome={"dynamics": dynamics})


def solve_explicit(case: Case, out: Path, resume: bool = False, progress: bool = False) -> Result:
    """Run the explicit dynamic analysis of ``case`` into the folder ``out`` (series, checkpoints);
    ``resume`` continues from the folder's checkpoint. BLAS is pinned to one thread, so that a resumed
    run repeats the uninterrupted one bit for bit."""
    from threadpoolctl import threadpool_limits

    out = Path(out)
    run = ExplicitRun(case, out, input_key(case))
    with threadpool_limits(1):
        # until this run ends nothing looks complete, and no state of an earlier run stays (only files a run
        # writes are removed; a resumed run keeps the checkpoint and series it continues, and removes nothing
        # before its checkpoint is accepted)
        out.mkdir(parents=True, exist_ok=True)
        if resume:
            run.resume()
            remove_outputs(out, resume=True)
            _prune_series(out, run.series.entries)
        else:
            remove_outputs(out)
            run.start()
        run.run(progress)
        return run.result()


def _prune_series(out: Path, entries: list[tuple[float, str]]) -> None:
    """Remove the states a killed run saved after its last checkpoint (``series/`` files not among the
    checkpoint's ``entries``, (time, file)) and rewrite the index to match: the resumed run writes them again,
    and the folder never lists or holds a state the resumed run did not reach."""
    listed = {name for _, name in entries}
    series = out / SERIES
    if series.is_dir():
        for p in series.iterdir():
            if STEP.fullmatch(p.name) and f"{SERIES}/{p.name}" not in listed:
                p.unlink()
    if entries:
        atomic_write_text(out / "result.pvd", pvd_text(entries))

