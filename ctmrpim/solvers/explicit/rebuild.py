"""Rebuilds of the explicit solver's frame, on two levels (Section 2.1.4; the paper's steps (3)-(4)).

**Rebuilds** (two levels). Once any point has been strained by more than ``rebuild_strain`` since the
last rebuild (largest |principal stretch - 1| of F: neighbouring nodes at d_c have then moved that
fraction of d_c relative to each other; a rigid motion never counts), the RPIM shape functions are
rebuilt on the current nodes at the points, which the body has carried with it (positions x_p + N (x -
x_r), weights w det F) and which keep their stress and plastic strain exactly. Once a point has been
strained by more than ``relay_strain`` since the points were laid, the boundary is re-tracked (alpha
shape) and new CTM points are laid over it (the paper's step (3)-(4)); the stress and plastic strain
are then L2-projected onto the nodes over the old points and evaluated at the new ones
(:mod:`ctmrpim.discretisation.state_transfer`); a new point whose projected state leaves the range of the old
values it depends on (:func:`~ctmrpim.discretisation.state_transfer.local_bounds`; where nodes crowd into a thin
layer the projection is singular to round-off) takes their convex average instead
(:func:`~ctmrpim.discretisation.state_transfer.convex_average`; such points are counted as ``clipped``),
projected stresses outside the yield surface are returned to it and counted, and the elastic energy the
projection changed is booked. Why two levels: laying new points and transferring the state at every rebuild
(measured on the 496-node collapse, 271 transfers) smooths the stress of a cohesionless body that sits at yield
almost everywhere, and the deposit kept creeping after the flow had stopped; carried points keep the state and
cost only the RPIM solve. A re-tracked area that differs from the previous re-tracking's by more than
``area_jump`` stops the run
(the alpha shape opened or closed a gap: the body is nearly isochoric, so its alpha shape keeps its
area). The carried points' area (sum of w det F) is not the reference: where the front thins out, the
cohesionless material dilates at zero stress (the Mohr-Coulomb apex) and the nodes spread beyond
alpha, so the carried domain grows while the alpha shape leaves the dispersed grains out (measured on
2016 nodes at t = 0.33 s: carried 0.0243 m^2, re-tracked 0.0198, initial 0.0200); that difference is
reported (``tracked_area.dispersed``). The stable time step is recomputed at every rebuild
(:mod:`ctmrpim.solvers.explicit.time_step`).

Where the alpha shape cannot be traced on the moved cloud (a pinch it cannot split; met once, on 2016
nodes at 0.18 s), the run goes on with the carried points and tries again at the next rebuild (counted).
"""
from __future__ import annotations

import numpy as np

from ctmrpim.discretisation.configuration import Configuration
from ctmrpim.discretisation.state_transfer import convex_average, local_bounds
from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import ELASTIC
from ctmrpim.materials.objective_stress import det_c, largest_strain_c
from ctmrpim.solvers.explicit.energy import elastic_density
from ctmrpim.solvers.explicit.errors import Diverged
from ctmrpim.solvers.explicit.frame import IDENTITY, project_onto_nodes


class Rebuilds:
    """The rebuilds of an :class:`~ctmrpim.solvers.explicit.run.ExplicitRun` (a mixin of it: replaces the
    run's ``frame`` and resets ``F``; on re-tracking, transfers ``stress``, ``plastic`` and ``viscous`` to the
    new points and resets ``laid``; counts ``rebuilds``, ``transfers``, ``clipped``, ``returned`` and the re-tracking
    failures; recomputes the time step)."""

    def rebuild_if_needed(self) -> bool:
        """Rebuild once a point has been strained by more than ``rebuild_strain`` since the last rebuild:
        the RPIM shape functions anew on the current nodes at the points carried with the body (their
        state kept as it is); once a point has been strained by more than ``relay_strain`` since the
        points were laid, the boundary is re-tracked and new CTM points laid, the state transferred."""
        s = self.settings
        known = self.strain_of_F          # the step's point pass measured it on its way
        if (known[1] if known is not None and known[0] is self.F else largest_strain_c(self.F)) <= s.rebuild_strain:
            return False
        old, F = self.frame, self.F
        f_old = self.force_of_state()
        w_now = old.w * det_c(F)
        self.laid = compose(F, self.laid)
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
                new = self.frame_at(self.x, old.free, old.moved_points(self.x), w_now, old.boundary.loops,
                                    old.boundary.triangles)
            except ProblemError as exc:
                raise Diverged(f"the rebuild at {when} failed: {exc.message}") from None
        self.timer.lap("rebuild")
        if relay:
            self._transfer_state(old, new, w_now)
        elif self.stage == "dynamic":
            # the carried points keep their state; the ones the new frame dropped take their elastic energy away
            self.energy.transfer += float((new.w - w_now) @ elastic_density(self.material, self.stress))
        self.frame = new
        self.F = np.tile(IDENTITY, (len(new.w), 1))
        f_new = self.force_of_state()
        if self.stage == "dynamic":       # energy.Energy.rebuild: the force's change over the last half step
            self.energy.rebuild += 0.5 * self.dt_previous * float(np.sum((f_new - f_old) * self.v))
        self.rebuilds += 1
        self.free_max = max(self.free_max, len(self.x) - len(new.active))
        self._time_step()
        self.timer.lap("time_step")
        return True

    def _transfer_state(self, old: Configuration, new: Configuration, w_now: np.ndarray) -> None:
        """The state of the points of ``old`` (current weights ``w_now``) onto the new points laid on the
        re-tracked boundary of ``new``: checks the re-tracked area, projects and returns to yield, books
        the elastic energy the transfer changed."""
        area, carried, previous = new.boundary.area, float(w_now.sum()) / self.thickness, self.areas[-1]
        self.area_changes.append(area / carried - 1.0)
        if abs(area - previous) > self.settings.area_jump * previous:
            raise Diverged(f"the re-tracked area {area:.6g} differs from the last re-tracking's {previous:.6g} "
                           f"({100 * (area / previous - 1):+.2f} %) at step {self.step}, t = {self.t:.6g} s: "
                           f"the alpha shape opened or closed a gap ({len(new.boundary.loops)} loop(s)); "
                           "change method.alpha, explicit.relay_strain or explicit.area_jump", key="method.alpha")
        elastic_before = float(w_now @ elastic_density(self.material, self.stress))
        carried = np.c_[self.stress, self.plastic, self.viscous]
        at_new = np.asarray(new.N @ project_onto_nodes(old, w_now, carried))
        lo, hi = local_bounds(old.N, w_now, carried, new.N)
        # a point whose projection leaves its old values' range by more than round-off of the component's scale
        # takes their convex average, whole (each component clipped alone would combine their extremes)
        slack = 1e-9 * np.abs(carried).max(axis=0)
        outside = np.flatnonzero(((at_new < lo - slack) | (at_new > hi + slack)).any(axis=1) & (new.w > 0))
        if len(outside):
            at_new[outside] = convex_average(old.N, w_now, carried, new.N, outside)
        at_new = np.clip(at_new, lo, hi)     # round-off only (a point out of every old point's reach has no bounds)
        self.clipped += len(outside)
        stress, region = self.material.update(at_new[:, :4], np.zeros((len(at_new), 3)))
        self.returned += int(np.count_nonzero(region != ELASTIC))
        self.stress, self.plastic, self.viscous = stress, at_new[:, 4:8], at_new[:, 8:]
        self.viscous[~(new.w > 0)] = 0.0
        if self.stage == "dynamic":
            self.energy.transfer += float(new.w @ elastic_density(self.material, stress)) - elastic_before
        self.laid = np.tile(IDENTITY, (len(new.w), 1))
        self.transfers += 1
        self.areas.append(area)
        self.timer.lap("transfer")


def compose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(m, 4) products a b of (m, 4) gradients stored xx, xy, yx, yy."""
    return np.stack([a[:, 0] * b[:, 0] + a[:, 1] * b[:, 2], a[:, 0] * b[:, 1] + a[:, 1] * b[:, 3],
                     a[:, 2] * b[:, 0] + a[:, 3] * b[:, 2], a[:, 2] * b[:, 1] + a[:, 3] * b[:, 3]], axis=1)
