"""Energy accounts of the explicit solver (Section 2.1.4; the energy check of the collapse, Section 3.4).

**Energy** (dynamic stage, from t = 0): the work of gravity, of the internal forces, of damping and of
the walls (their velocity corrections) is summed over the displacements dt (v_{n+1/2} + v_{n-1/2}) / 2,
for which central differences balance energy exactly (any sequence of dt): W_gravity + W_damping +
W_walls - W_internal = kinetic energy, to round-off (a check of the bookkeeping). Independently, at the
points: elastic energy, plastic dissipation sum w sigma : d eps_p, viscous dissipation and the elastic energy
that the rebuilds changed (the state transfers, and the points dropped by a rebuild or inverted by a step, whose
stress leaves with them); W_internal against their sum measures the discretisation's error (the "material
balance"). One more account is the rebuilds': W_internal books step n + 1's force over the second half of step n's
displacement, (x_{n+1} - x_n) / 2, and a rebuild between them changes that force (new shape functions, and with a
relay a transferred state), so it books 0.5 (F_int,new - F_int,old) . (x_{n+1} - x_n) that the material never saw;
each rebuild books it (``rebuild``; measured on the 496-node collapse's first 700 steps, six rebuilds: 6.6e-5 of the
gravity work).

The works are booked by the step (:mod:`ctmrpim.solvers.explicit.step`), the transfers' change by the
rebuilds (:mod:`ctmrpim.solvers.explicit.rebuild`); both balances are reported by
:meth:`ctmrpim.solvers.explicit.run.ExplicitRun.result`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ctmrpim.materials.mohr_coulomb import MohrCoulomb, elastic_strain
from ctmrpim.materials.objective_stress import det_c


@dataclass
class Energy:
    """Energy accounts of the dynamic stage (J per unit thickness times the thickness)."""

    gravity: float = 0.0       # work of gravity
    internal: float = 0.0      # work of the internal forces (stored + dissipated by the material)
    damping: float = 0.0       # work of the damping forces (<= 0)
    walls: float = 0.0         # work of the wall and support corrections (<= 0: dissipated by contact)
    plastic: float = 0.0       # plastic dissipation at the points
    transfer: float = 0.0      # elastic energy changed by the rebuilds (state transfers, dropped points)
    viscous: float = 0.0       # dissipated by the viscous stress (explicit.viscosity)
    rebuild: float = 0.0       # internal work the rebuilds' change of the force adds over the half step before them
    elastic0: float = 0.0      # elastic energy at t = 0


class StoredEnergy:
    """The energies held by the present state of an :class:`~ctmrpim.solvers.explicit.run.ExplicitRun` (a
    mixin of it: reads the run's ``material``, ``mass``, ``v``, ``frame``, ``F`` and ``stress``)."""

    def elastic_energy(self) -> float:
        """sum w det F sigma : C sigma / 2 over the points (the weights of the current configuration)."""
        return float((self.frame.w * det_c(self.F)) @ elastic_density(self.material, self.stress))

    def kinetic_energy(self) -> float:
        """0.5 sum m |v|^2 at the half step."""
        return 0.5 * float(self.mass @ np.einsum("nd,nd->n", self.v, self.v))


def elastic_density(material: MohrCoulomb, stress: np.ndarray) -> np.ndarray:
    """sigma : C sigma / 2 (m,) of the stresses (m, 4) xx, yy, xy, zz."""
    return 0.5 * contract(stress, elastic_strain(material, stress))


def contract(s: np.ndarray, e: np.ndarray) -> np.ndarray:
    """s : e (m,) of (m, 4) tensors stored xx, yy, xy, zz."""
    return s[:, 0] * e[:, 0] + s[:, 1] * e[:, 1] + 2.0 * s[:, 2] * e[:, 2] + s[:, 3] * e[:, 3]
