"""What an explicit run writes as it goes: a VTU of the nodal fields per ``save_every`` seconds with the
``.pvd`` index (:class:`ctmrpim.io.vtu.SeriesWriter`, written as the run goes, so a long run can be watched
and a killed one keeps its states), and the history records of ``summary.json``.
"""
from __future__ import annotations

import numpy as np

from ctmrpim.discretisation.nodal_average import RADIUS, KernelAverage
from ctmrpim.io.vtu import stress_point_data
from ctmrpim.materials.mohr_coulomb import equivalent_plastic_strain
from ctmrpim.materials.objective_stress import det_c
from ctmrpim.solvers.explicit.frame import project_onto_nodes


class SeriesOutput:
    """The output of an :class:`~ctmrpim.solvers.explicit.run.ExplicitRun` (a mixin of it: reads the run's
    state, writes into its ``series`` and ``history``)."""

    def nodal_fields(self) -> dict[str, np.ndarray]:
        """Stress projected onto the nodes and the equivalent plastic strain averaged there, with u and velocity:
        ``u`` and ``velocity`` (n, 3) (z = 0), ``displacement`` (n,) |u|, ``stress`` (n, 3) xx, yy, xy, ``szz``
        (n,), ``plastic_strain`` (n,) the equivalent plastic strain: a non-negative weighted mean of the points'
        within 2 d_c of the current positions (:mod:`ctmrpim.discretisation.nodal_average`; the projection
        went down to -1.3 beside the collapse's shear bands), zero at the free particles."""
        fr = self.frame
        w = fr.w * det_c(self.F)
        nodal = project_onto_nodes(fr, w, self.stress)
        n = len(self.x)
        plastic = np.zeros(n)
        body = fr.active
        plastic[body] = KernelAverage(self.x[body], fr.moved_points(self.x), w, RADIUS * self.d_c)(
            equivalent_plastic_strain(self.plastic)[:, None])[:, 0]
        zeros = np.zeros((n, 1))
        u = self.x - self.X
        return {"u": np.c_[u, zeros], "velocity": np.c_[self.v, zeros], "displacement": np.linalg.norm(u, axis=1),
                "stress": nodal[:, :3], "szz": nodal[:, 3], "plastic_strain": plastic}

    def save(self) -> None:
        """Add the present state to the series (a VTU and its entry in the ``.pvd`` index): the nodes, the
        frame's tracked boundary and its triangles moved with them, the stress as ParaView's tensor."""
        fields = self.nodal_fields()
        point_data = {**fields, **stress_point_data(fields.pop("stress"), fields.pop("szz"))}
        boundary = self.frame.boundary
        self.series.add(self.t, self.x, [("line", boundary.edges), ("triangle", boundary.triangles)], point_data)
        self.timer.lap("output")

    def record(self) -> None:
        """Append a history record: energies, works, largest speed, front, top, rebuilds."""
        ke = self.kinetic_energy()
        speed = np.linalg.norm(self.v, axis=1)
        e = self.energy
        self.history.append({"time": self.t, "step": self.step, "dt": self.dt, "kinetic": ke,
                             "elastic": self.elastic_energy(), "gravity_work": e.gravity, "internal_work": e.internal,
                             "plastic_dissipation": e.plastic, "wall_work": e.walls, "damping_work": e.damping,
                             "max_speed": float(speed.max()), "front": float(self.x[:, 0].max()),
                             "top": float(self.x[:, 1].max()), "rebuilds": self.rebuilds,
                             "free_particles": len(self.x) - len(self.frame.active)})

