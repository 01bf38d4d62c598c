"""Quasi-static small-strain elastoplastic CTM-RPIM (Section 2.1.3) with the Mohr-Coulomb material.

Small strain (the slope and the footing never re-track): boundary, CTM points and RPIM shape functions
are built once on the reference configuration and handed to the method-agnostic equilibrium of
:mod:`ctmrpim.solvers.plastic_system` (load stepping, strength reduction, dynamic relaxation), which the
finite-element reference drives with its own discretisation. The stress history lives at the CTM points.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ctmrpim.discretisation import assembly
from ctmrpim.discretisation.boundary_loads import BoundaryLoads
from ctmrpim.discretisation.configuration import build_configuration
from ctmrpim.discretisation.lagrangian_operators import gradient_operator
from ctmrpim.discretisation.rpim import shape_functions
from ctmrpim.discretisation.state_transfer import NodalProjection
from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.problem.case import Case
from ctmrpim.result import Result, probe_record
from ctmrpim.solvers.plastic_system import PlasticOutput, PlasticSystem, run_elastoplastic
from ctmrpim.timing import Timer


def ctm_plastic_system(case: Case, timer: Timer):
    """The CTM-RPIM discretisation of a Mohr-Coulomb Case as a :class:`PlasticSystem`, with the
    configuration it was built on."""
    problem = case.problem
    if not isinstance(problem.material, MohrCoulomb):
        raise ProblemError("the elastoplastic solver needs model = \"mohr-coulomb\"", key="material.model")
    if any(t.follower for t in problem.tractions):
        raise ProblemError("follower loads need a large-deformation material; the Mohr-Coulomb solver is "
                           "small-strain", key="traction")
    conf = build_configuration(case, timer)
    nodes, quad, sf = conf.disc.nodes, conf.disc.quadrature, conf.sf
    w = quad.weights * problem.thickness
    q = conf.traction
    loads = BoundaryLoads(conf.sf_traction.N, q.weights * problem.thickness, conf.tx, conf.ty, q.ends, q.follower,
                          nodes[q.ends[:, 1]] - nodes[q.ends[:, 0]],
                          problem.thickness * assembly.point_load_vector(nodes, problem, conf.rpim))
    system = PlasticSystem(gradient_operator(sf.dNdx, sf.dNdy), w, conf.fixed, conf.fixed_values,
                           lambda factor: loads.forces(nodes, factor)[0],
                           assembly.body_force_vector(sf.N, w, problem), problem.material,
                           tangent=case.loading.tangent)
    return system, conf


def solve_elastoplastic(case: Case, progress: Callable[[Any], None] = lambda level: None) -> Result:
    """:func:`run_elastoplastic` with CTM-RPIM."""
    problem = case.problem
    timer = Timer()
    system, conf = ctm_plastic_system(case, timer)
    nodes, sf = conf.disc.nodes, conf.sf
    probe_xy = np.array([[p.x, p.y] for p in problem.probes]).reshape(-1, 2)
    sf_p = shape_functions(nodes, probe_xy, derivatives=False, **conf.rpim) if len(probe_xy) else None
    timer.lap("assembly")

    nodal = NodalProjection(sf.N, system.w)

    def probe_values(U: np.ndarray, stress: np.ndarray | None) -> dict:
        if sf_p is None:
            return {}
        up = sf_p.N @ U.reshape(-1, 2)
        sp_ = sf_p.N @ nodal(stress) if stress is not None else np.full((len(up), 3), np.nan)
        return {p.name: probe_record(p.x, p.y, up[i], sp_[i]) for i, p in enumerate(problem.probes)}

    sizes = sf.support_sizes
    material = problem.material
    out = PlasticOutput(
        method="ctm-rpim-mc", points=nodes, cells=[("line", conf.disc.boundary.edges)],
        displacement=lambda U: U.reshape(-1, 2).copy(), nodal=nodal, probe_values=probe_values,
        peak_traction=float(np.hypot(conf.tx, conf.ty).max(initial=0.0)),
        counts={"nodes": len(nodes), "integration_points": len(system.w),
                "support_size": {"min": int(sizes.min()), "mean": float(sizes.mean()), "max": int(sizes.max())}},
        parameters={**case.resolved, "derived": {"d_c": conf.disc.d_c, "G": material.G, "K": material.K}})
    return run_elastoplastic(case, system, out, timer, progress)
