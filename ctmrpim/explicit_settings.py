"""The ``[explicit]`` table of a problem file: settings of the explicit dynamic solver
(:mod:`ctmrpim.explicit_dynamics`, where each is explained)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .errors import ProblemError


@dataclass(frozen=True)
class Explicit:
    """The ``[explicit]`` table of a problem file."""

    duration: float = 1.0          # simulated time after the gate is removed (s)
    dt: float | str = "cfl"        # time step (s), or "cfl": cfl x 2 / omega_max, recomputed at each rebuild
    cfl: float = 0.5
    damping: float = 0.0           # local damping factor f of Eq. (11); 0: true dynamics
    viscosity: float = 0.0         # beta (s): stiffness-proportional damping, a viscous stress beta D d(eps)/dt
    rebuild_strain: float = 0.2    # RPIM rebuilt once a point is strained this much since the last rebuild
    relay_strain: float = 1.0      # boundary re-tracked, CTM points laid anew (state transferred) once a point
                                   # is strained this much since the points were laid
    area_jump: float = 0.02        # the run stops when a re-tracked area jumps by more than this fraction
    save_every: float = 0.01       # simulated seconds between saved states (VTU series)
    checkpoint_every: int = 1000   # steps between checkpoints (0: none)
    rest: float = 1e-4             # at rest once the kinetic energy is below rest x its peak
    initial: str = "gravity"       # "gravity": damped stage with the gates in place; "none": start unstressed
    stage_damping: float = 0.8     # local damping of the gravity stage
    stage_tolerance: float = 1e-3  # the stage ends when the out-of-balance force is below this x the weight
    stage_steps: int = 20000       # at most this many steps in the gravity stage
    detached: str = "stop"         # a node that leaves the body: "stop" the run, or let it go "free"

    def __post_init__(self) -> None:
        checks = (("duration", self.duration > 0, "must be > 0"),
                  ("dt", self.dt == "cfl" or (isinstance(self.dt, (int, float)) and not isinstance(self.dt, bool)
                                              and self.dt > 0), "must be \"cfl\" or a time step > 0 (s)"),
                  ("cfl", 0 < self.cfl <= 1, "must lie in (0, 1]"),
                  ("damping", 0 <= self.damping < 1, "must lie in [0, 1)"),
                  ("viscosity", self.viscosity >= 0, "must be >= 0 (s)"),
                  ("rebuild_strain", self.rebuild_strain > 0, "must be > 0"),
                  ("relay_strain", self.relay_strain >= self.rebuild_strain, "must be >= rebuild_strain"),
                  ("area_jump", 0 < self.area_jump < 1, "must lie in (0, 1)"),
                  ("save_every", self.save_every > 0, "must be > 0 (s)"),
                  ("checkpoint_every", _count(self.checkpoint_every, 0), "must be an integer >= 0"),
                  ("rest", 0 < self.rest < 1, "must lie in (0, 1)"),
                  ("initial", self.initial in ("gravity", "none"), "must be \"gravity\" or \"none\""),
                  ("stage_damping", 0 <= self.stage_damping < 1, "must lie in [0, 1)"),
                  ("stage_tolerance", 0 < self.stage_tolerance < 1, "must lie in (0, 1)"),
                  ("stage_steps", _count(self.stage_steps, 1), "must be an integer >= 1"),
                  ("detached", self.detached in ("stop", "free"), "must be \"stop\" or \"free\""))
        for key, ok, why in checks:
            if not ok:
                raise ProblemError(f"{getattr(self, key)!r} {why}", key=f"explicit.{key}")


def _count(value: Any, least: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= least
