"""One central-difference step of the explicit solver (Section 2.1.4, Eqs. 8-11).

    M a = F_ext - F_int + F_damp,       F_damp = -f |F_ext - F_int| sign(v)                  (Eqs. 9-11)

Central differences with the half-step velocity: v_{n+1/2} = v_{n-1/2} + h M^-1 F_n, h = (dt_{n-1} + dt_n) / 2
(the step changes at rebuilds; the first step takes the velocity it starts from as v_{-1/2}, h = dt_0), then
contact with the rigid walls (:mod:`ctmrpim.solvers.explicit.contact`) and fixed dofs, x_{n+1} = x_n + dt_n v_{n+1/2}.
M is the lumped mass of the initial cloud (:mod:`ctmrpim.discretisation.lumped_mass`: positive, constant, so mass is
conserved exactly), F_ext the nodal weight m g, f = 0 by default (true dynamics). F_int and the stress
update act on the frame (:mod:`ctmrpim.solvers.explicit.frame`); the step books the works of the energy
accounts (:mod:`ctmrpim.solvers.explicit.energy`).

**Viscosity** (``viscosity`` = beta, s; default 0): stiffness-proportional (Rayleigh) damping, a viscous
stress beta D d(eps)/dt at the points added to the Cauchy stress in F_int (not to the stress state that
yields), lagged by one step as explicit codes do; a mode of frequency omega gets the damping ratio
beta omega / 2, and the stable step becomes cfl 2 / omega_max (sqrt(1 + z^2) - z), z = beta omega_max / 2
(:mod:`ctmrpim.solvers.explicit.time_step`).
Why: the paper's model (rate-independent Mohr-Coulomb, no damping) lets the surface layer of the
collapsed column slide on long after the flow has stopped (on 496 nodes it still moved at 1 s and its
surface flattened well below the experiment's; study ``column_collapse_viscosity`` has the numbers); SPH models of granular flow, the method the
experiment was first compared with, carry an artificial viscosity, and a real granular flow's friction
grows with its shear rate (the mu(I) rheology), which a rate-independent model lacks. The value is a
setting, fitted for the benchmark (study ``column_collapse_viscosity``). The per-point work is in
:mod:`ctmrpim.materials.mohr_coulomb_kernel` and the pass over the points, which also scatters the next step's
internal force, in :mod:`ctmrpim.solvers.explicit.point_pass` (compiled); the nodal update, walls and works in
:mod:`ctmrpim.solvers.explicit.nodal_update` (compiled).

**Inverted points**: a point which one step turns inside out gets weight 0, like the points dropped by
the frame (it integrates nothing; counted in ``summary.json``). More than INVERTED_LIMIT of the points
inverted by one step is an unstable step: the run stops.
"""
from __future__ import annotations

import numpy as np

from ctmrpim.materials.mohr_coulomb import MohrCoulomb, plastic_strain_increment
from ctmrpim.materials.mohr_coulomb_kernel import PointUpdate
from ctmrpim.materials.objective_stress import det_c, hughes_winget_c, relative_c, rotate_c
from ctmrpim.materials.objective_stress_kernels import weighted_first_piola
from ctmrpim.problem.model import Wall
from ctmrpim.solvers.explicit.contact import wall_table
from ctmrpim.solvers.explicit.energy import contract, elastic_density
from ctmrpim.solvers.explicit.errors import Diverged
from ctmrpim.solvers.explicit.frame import IDENTITY
from ctmrpim.solvers.explicit.nodal_update import nodal_update
from ctmrpim.solvers.explicit.point_pass import point_pass

#: More than this share of the integrating points inverted by one step: the step is unstable.
INVERTED_LIMIT = 0.01


class CentralDifference:
    """The step of an :class:`~ctmrpim.solvers.explicit.run.ExplicitRun` (a mixin of it: advances the run's
    ``x``, ``v``, ``F``, ``stress``, ``plastic``, ``viscous``, ``t`` and ``step`` on its ``frame``, and books
    into ``energy`` in the dynamic stage, into ``stage_residual`` in the gravity stage)."""

    def advance(self, walls: list[Wall], damping: float) -> None:
        """One central-difference step from (x_n, v_{n-1/2}, stress_n) to (x_{n+1}, v_{n+1/2}, stress_{n+1})."""
        fr, dt, F = self.frame, self.dt, self.F
        viscosity = bool(self.settings.viscosity)
        f_int = self.force_of_state()
        v, x, f = np.empty_like(self.v), np.empty_like(self.x), np.empty_like(self.x)
        works = np.zeros(4 if self.stage == "dynamic" else 0)
        h = 0.5 * (self.dt_previous + dt)      # from v_{n-1/2} to v_{n+1/2} (nodal_update's docstring)
        bad = nodal_update(f_int, self.weight, self.mass, self.movable, self.v, self.x, dt, h, float(damping),
                           wall_table(tuple(walls)), works, v, x, f)
        if bad >= 0:
            raise Diverged(f"non-finite velocity at node #{bad} ({self.x[bad, 0]:.5g}, {self.x[bad, 1]:.5g}) at step "
                           f"{self.step}, t = {self.t:.6g} s")
        if self.stage == "gravity":
            self.stage_residual = out_of_balance(f, walls, self.movable, self.x, self.weight, self.d_c)
        else:
            e = self.energy
            e.gravity += float(works[0])
            e.internal += float(works[1])
            e.damping += float(works[2])
            e.walls += float(works[3])
        self.timer.lap("forces")
        if self.material.tension is None:
            upd = point_pass(fr, x - fr.x, F, self.stress, self.plastic, self.viscous, self.material,
                             self.settings.viscosity / dt, viscosity, force=fr.tested is None)
            self._drop_inverted(upd.inverted, x, F)
            F_new, self.strain_of_F = upd.F, (upd.F, upd.largest_strain)
            self.force_of_F = None if upd.force is None else (upd.F, fr, upd.force)
        else:
            F_new = fr.gradient(x - fr.x)
            f_inc = relative_c(F_new, F)
            self._drop_inverted(~(det_c(f_inc) > 0) & (fr.w > 0), x, F)
            dead = ~(fr.w > 0)
            if dead.any():
                f_inc[dead], F_new[dead] = IDENTITY, IDENTITY
            upd = point_update_numpy(self.material, f_inc, self.stress, self.plastic, dead, fr.w * det_c(F_new))
            self.force_of_F = None
        if self.stage == "dynamic":
            self.energy.plastic += upd.dissipation
            self.energy.viscous += upd.viscous_work
        self.timer.lap("material")
        self.x, self.v, self.F = x, v, F_new
        self.stress, self.plastic, self.viscous = upd.stress, upd.plastic, upd.viscous
        self.t += dt
        self.dt_previous = dt
        self.step += 1

    def force_of_state(self) -> np.ndarray:
        """(n, 2) F_int of the present state on the present frame: the last point pass's where it scattered it on
        its way, else computed, and kept for the next call (the same kernel and blocks, the same bits)."""
        known = self.force_of_F
        if known is not None and known[0] is self.F and known[1] is self.frame:
            return known[2]
        wP = np.empty((len(self.frame.w), 4))
        weighted_first_piola(self.stress, self.viscous, bool(self.settings.viscosity), self.F, self.frame.w, wP)
        force = self.frame.weighted_force(wP)
        self.force_of_F = (self.F, self.frame, force)
        return force

    def _drop_inverted(self, inverted: np.ndarray, x: np.ndarray, F: np.ndarray) -> None:
        """A point the step turns inside out (``inverted`` (m,)): a few at a ragged front are dropped like the points
        without shape functions (weight 0, no stress, counted); many at once is an unstable step (x (n, 2) the
        nodes after it, F (m, 4) the gradients before it, for the diagnosis)."""
        if not inverted.any():
            return
        fr = self.frame
        if inverted.sum() > INVERTED_LIMIT * np.count_nonzero(fr.w):
            J = det_c(relative_c(fr.gradient(x - fr.x), F))
            i = int(np.argmin(np.where(inverted, np.where(np.isfinite(J), J, -np.inf), np.inf)))
            p = fr.moved_points(x)[i]
            raise Diverged(f"the step inverts the material at {int(inverted.sum())} integration points (det f = "
                           f"{J[i]:.3g} at #{i} near ({p[0]:.5g}, {p[1]:.5g})) at step {self.step}, t = "
                           f"{self.t:.6g} s; use a smaller explicit.dt or explicit.cfl")
        if self.stage == "dynamic":     # the step leaves them stress-free: their elastic energy leaves with them
            self.energy.transfer -= float((fr.w[inverted] * det_c(F[inverted]))
                                          @ elastic_density(self.material, self.stress[inverted]))
        fr.w[inverted] = 0.0
        self.dropped_points += int(inverted.sum())


def point_update_numpy(material: MohrCoulomb, f_inc: np.ndarray, stress: np.ndarray, plastic: np.ndarray,
                       dead: np.ndarray, w: np.ndarray) -> PointUpdate:
    """:func:`ctmrpim.materials.mohr_coulomb_kernel.point_update` in numpy forms, for the tension cut-off
    (no viscosity: refused with a tension cut-off): relative gradients ``f_inc`` (m, 4: xx, xy, yx, yy),
    the last step's stress and plastic strain (m, 4: xx, yy, xy, zz), the points ``dead`` (m,) and the
    weights ``w`` (m,) of the plastic dissipation."""
    strain, c, s = hughes_winget_c(f_inc)
    rotated = rotate_c(stress, c, s)
    plastic = rotate_c(plastic, c, s)
    stress, region = material.update(rotated, strain)
    dp = plastic_strain_increment(material, strain, stress - rotated)
    stress[dead], plastic[dead], dp[dead] = 0.0, 0.0, 0.0
    return PointUpdate(stress, plastic + dp, region, float(w @ contract(0.5 * (rotated + stress), dp)),
                       np.zeros_like(stress), 0.0)


def out_of_balance(f: np.ndarray, walls: list[Wall], movable: np.ndarray, x: np.ndarray, weight: np.ndarray,
                   d_c: float) -> float:
    """|F_ext - F_int| over the weight, without what supports and walls in contact take: ``f`` (n, 2) the
    nodal F_ext - F_int, ``movable`` (n, 2) the free dofs, ``x`` (n, 2) the nodes, ``weight`` (n, 2) m g."""
    r = np.where(movable, f, 0.0)
    for wall in walls:
        n = np.asarray(wall.normal)
        pressed = (wall.gap(x) <= 1e-9 * d_c) & (r @ n < 0)
        rn = r[pressed] @ n
        r[pressed] = wall.slip(r[pressed] - rn[:, None] * n, rn)   # the wall takes the normal part
    return float(np.linalg.norm(r) / np.linalg.norm(weight))
