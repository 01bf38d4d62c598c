"""The state of an explicit run: what it holds, how it starts, its checkpoints and resume.

A checkpoint every ``checkpoint_every`` steps (:mod:`ctmrpim.io.checkpoint`) holds everything the next step
needs, from which ``--resume`` continues bit for bit (docs/design.md, 'Explicit dynamics'): the frame is
rebuilt from x_r (the positions, points, weights and boundary it was built on are stored), and BLAS is
pinned to one thread (:func:`ctmrpim.solvers.explicit.run.solve_explicit`). A checkpoint resumes only the
run that wrote it (:func:`input_key`); a run that diverges leaves its last checkpoint as it was.
"""
from __future__ import annotations

import hashlib
import json
from dataclasses import asdict
from typing import Any

import numpy as np

from ctmrpim.discretisation.configuration import Configuration
from ctmrpim.io.checkpoint import load_checkpoint, save_checkpoint
from ctmrpim.io.vtu import SeriesWriter
from ctmrpim.problem.case import Case
from ctmrpim.solvers.explicit.energy import Energy
from ctmrpim.solvers.explicit.frame import IDENTITY
from ctmrpim.solvers.explicit.time_step import checkerboard, smallest_spacing, wave_speed_step


class RunState:
    """The evolving state of an :class:`~ctmrpim.solvers.explicit.run.ExplicitRun` (a mixin of it; the
    set-up it reads, ``X``, ``material``, ``settings``, ``out``, ``key``, is the run's): declared here, set
    by :meth:`start` or :meth:`resume`, saved by :meth:`checkpoint`. n nodes, m points; point tensors are
    (m, 4), stresses and strains stored xx, yy, xy, zz, gradients xx, xy, yx, yy."""

    x: np.ndarray                   # (n, 2) node positions
    v: np.ndarray                   # (n, 2) velocities at the half step
    frame: Configuration            # the configuration the points are built on (x_r, points, RPIM)
    stress: np.ndarray              # (m, 4) Cauchy stress at the points
    plastic: np.ndarray             # (m, 4) plastic strain
    viscous: np.ndarray             # (m, 4) viscous stress of the last step
    F: np.ndarray                   # (m, 4) deformation gradient relative to the frame
    strain_of_F: tuple[np.ndarray, float] | None = None   # (F, its largest stretch strain), as the step measured it
    force_of_F: tuple[np.ndarray, Configuration, np.ndarray] | None = None   # (F, frame, F_int there), as the step
                                    # scattered it for the stress it left (to be cleared where that stress changes)
    laid: np.ndarray                # (m, 4) deformation gradient since the points were laid, up to the frame
    mode: np.ndarray                # (n, 2) the time step estimate's vector
    dt: float                       # the time step
    omega: float                    # the frame's largest circular frequency (omega_max)
    dt_range: list[float]           # [smallest, largest] time step so far
    dt_wave: float                  # the wave-speed bound, reported
    stage: str                      # "gravity" (the damped initial stage) or "dynamic"
    t: float                        # time of the dynamic stage (s)
    step: int                       # steps of the dynamic stage
    stage_steps: int                # steps of the gravity stage
    rebuilds: int                   # rebuilds, state transfers, transferred stresses returned to yield
    transfers: int
    returned: int
    clipped: int                    # transferred points out of their old values' range (convex average instead)
    areas: list[float]              # area of the body at each re-tracking (the first: the initial one)
    area_changes: list[float]       # re-tracked over carried area - 1 at each re-tracking
    free_max: int                   # most free particles at once
    relay_failures: int             # re-trackings that failed, the first's reason
    relay_failure: str
    energy: Energy
    ke_peak: float                  # largest kinetic energy so far, whether at rest (kinetic < rest x peak)
    at_rest: bool
    stage_residual: float           # out-of-balance force of the gravity stage over the weight
    history: list[dict[str, Any]]   # records of summary.json
    series: SeriesWriter
    next_save: float                # time of the next VTU, of the next history record
    next_record: float

    def start(self) -> None:
        """The state at rest before the first step: the reference cloud, points laid on it, no stress."""
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
        self.dt_wave = wave_speed_step(smallest_spacing(self.X), self.material.E, self.material.nu,
                                       self.material.density)
        self.stage = "gravity" if self.settings.initial == "gravity" else "dynamic"
        self.t, self.step, self.stage_steps = 0.0, 0, 0
        self.dt_previous = self.dt       # the last step's dt; the first step's own: v is taken as v_{-1/2}
        self.rebuilds, self.transfers, self.returned, self.areas, self.free_max = 0, 0, 0, [self.frame.boundary.area], 0
        self.clipped = 0
        self.area_changes = []
        self.relay_failures, self.relay_failure = 0, ""
        self.energy = Energy()
        self.ke_peak, self.at_rest, self.stage_residual = 0.0, False, np.inf
        self.history = []
        self.series = SeriesWriter(self.out)
        self.next_save, self.next_record = 0.0, 0.0
        self.timer.lap("set_up")

    def _arrays(self) -> dict[str, np.ndarray]:
        fr = self.frame
        return {"x": self.x, "v": self.v, "frame_x": fr.x, "frame_free": fr.free,
                "frame_points": fr.points, "frame_w": fr.w, "frame_loops": np.concatenate(fr.boundary.loops),
                "frame_loop_sizes": [len(lp) for lp in fr.boundary.loops], "frame_triangles": fr.boundary.triangles,
                "laid": self.laid, "stress": self.stress,
                "plastic": self.plastic, "viscous": self.viscous, "F": self.F, "mode": self.mode}

    def _meta(self) -> dict[str, Any]:
        return {"stage": self.stage, "t": self.t, "step": self.step, "stage_steps": self.stage_steps,
                "dt": self.dt, "dt_previous": self.dt_previous, "omega": self.omega, "dt_range": self.dt_range,
                "dt_wave": self.dt_wave, "rebuilds": self.rebuilds, "transfers": self.transfers,
                "returned": self.returned, "clipped": self.clipped, "areas": self.areas,
                "area_changes": self.area_changes, "free_max": self.free_max, "relay_failures": self.relay_failures,
                "relay_failure": self.relay_failure, "dropped_points": self.dropped_points, "tracking": self.tracking,
                "energy": asdict(self.energy), "ke_peak": self.ke_peak, "stage_residual": self.stage_residual,
                "history": self.history, "series": self.series.entries, "next_save": self.next_save,
                "next_record": self.next_record}

    def checkpoint(self) -> None:
        """Write the state into ``out``'s checkpoint (atomically)."""
        save_checkpoint(self.out, self.key, self._meta(), self._arrays())

    def resume(self) -> None:
        """The state of ``out``'s checkpoint, the frame rebuilt from it bit for bit."""
        meta, a = load_checkpoint(self.out, self.key)
        self.x, self.v = a["x"], a["v"]
        loops = np.split(a["frame_loops"], np.cumsum(a["frame_loop_sizes"])[:-1])
        self.frame = self.frame_at(a["frame_x"], a["frame_free"], a["frame_points"], a["frame_w"], loops,
                                   a["frame_triangles"])
        self.stress, self.plastic, self.F, self.mode = a["stress"], a["plastic"], a["F"], a["mode"]
        self.viscous = a["viscous"]
        self.laid = a["laid"]
        for k in ("stage", "t", "step", "stage_steps", "dt", "dt_previous", "omega", "dt_range", "dt_wave", "rebuilds",
                  "transfers", "returned", "clipped", "areas", "area_changes", "free_max", "relay_failures",
                  "relay_failure", "dropped_points", "tracking", "ke_peak", "stage_residual", "history", "next_save",
                  "next_record"):
            setattr(self, k, meta[k])
        self.energy = Energy(**meta["energy"])
        self.at_rest = False
        self.series = SeriesWriter(self.out, meta["series"])
        self.timer.lap("set_up")


def input_key(case: Case) -> str:
    """Hash of the resolved input and the code version: a checkpoint resumes only the same run."""
    from ctmrpim.io.provenance import code_version
    text = json.dumps({"resolved": case.resolved, "version": code_version()}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()
