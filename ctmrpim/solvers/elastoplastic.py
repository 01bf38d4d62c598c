"""Quasi-static small-strain elastoplastic CTM-RPIM (Section 2.1.3) with the Mohr-Coulomb material.

Small strain (the slope and the footing never re-track): boundary, CTM points and RPIM shape functions
are built once on the reference configuration and handed to the method-agnostic equilibrium of
:mod:`ctmrpim.solvers.plastic_system` (load stepping, strength reduction, dynamic relaxation), which the
finite-element reference drives with its own discretisation. The stress history lives at the CTM points.
"""
from __future__ import annotations

from typing import Any, Callable

import numpy as np
import scipy.sparse as sp

from ctmrpim.discretisation import assembly, consistent_integration
from ctmrpim.discretisation.boundary_loads import reference_loads
from ctmrpim.discretisation.configuration import BoundaryTags, Configuration, boundary_tags, reference_configuration
from ctmrpim.discretisation.nodal_average import RADIUS, KernelAverage
from ctmrpim.discretisation.point_products import PointProducts
from ctmrpim.discretisation.state_transfer import NodalProjection
from ctmrpim.errors import ProblemError
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.problem.case import Case
from ctmrpim.result import Result, probe_record
from ctmrpim.solvers.plastic_analysis import PlasticOutput, run_elastoplastic
from ctmrpim.solvers.plastic_system import PlasticSystem
from ctmrpim.timing import Timer


def ctm_plastic_system(case: Case, timer: Timer) -> tuple[PlasticSystem, Configuration, BoundaryTags]:
    """The CTM-RPIM discretisation of a Mohr-Coulomb Case as a :class:`PlasticSystem`, with the
    configuration it was built on and the boundary tags of that configuration."""
    problem = case.problem
    if not isinstance(problem.material, MohrCoulomb):
        raise ProblemError("the elastoplastic solver needs model = \"mohr-coulomb\"", key="material.model")
    if any(t.follower for t in problem.tractions):
        raise ProblemError("follower loads need a large-deformation material; the Mohr-Coulomb solver is "
                           "small-strain", key="traction")
    conf = reference_configuration(case, timer)
    tags = boundary_tags(case, conf.x, conf.boundary, conf.lengths)
    loads = reference_loads(conf, tags, problem.thickness, conf.point_forces(problem))
    test, dirichlet = _consistent(case, conf, tags) if case.method.integration == "ctm-vci" else (None, None)
    system = PlasticSystem(conf.block_gradient(), conf.w, tags.fixed, tags.fixed_values,
                           lambda factor: loads.forces(conf.x, factor)[0],
                           assembly.body_force_vector(conf.N, conf.w, problem), problem.material,
                           tangent=case.loading.tangent, test=test, dirichlet=dirichlet,
                           products=PointProducts.build(conf.block_gradient(), test, conf.w), nodes=conf.x)
    return system, conf, tags


def _consistent(case: Case, conf: Configuration, tags: BoundaryTags
                ) -> tuple[sp.bsr_matrix, consistent_integration.RecoveredDirichletTerm]:
    """``method.integration = "ctm-vci"``: G of the corrected test gradients, and the Dirichlet consistency term
    with the stress recovered at the boundary's Gauss points from the points' (the history lives there)."""
    test, term, _ = consistent_integration.recovered_consistency(conf, case.method, case.problem.thickness, tags.fixed)
    return test, term


def solve_elastoplastic(case: Case, progress: Callable[[Any], None] = lambda level: None) -> Result:
    """:func:`run_elastoplastic` with CTM-RPIM."""
    problem = case.problem
    timer = Timer()
    system, conf, tags = ctm_plastic_system(case, timer)
    nodes, sf = conf.x, conf.sf
    probe_xy = np.array([[p.x, p.y] for p in problem.probes]).reshape(-1, 2)
    sf_p = conf.shape_functions_at(probe_xy, derivatives=False) if len(probe_xy) else None
    timer.lap("assembly")

    nodal = NodalProjection(sf.N, system.w)
    average = KernelAverage(nodes, conf.points, system.w, RADIUS * conf.lengths.d_c)

    def probe_values(U: np.ndarray, stress: np.ndarray | None) -> dict:
        if sf_p is None:
            return {}
        up = sf_p.N @ U.reshape(-1, 2)
        sp_ = sf_p.N @ nodal(stress) if stress is not None else np.full((len(up), 3), np.nan)
        return {p.name: probe_record(p.x, p.y, up[i], sp_[i]) for i, p in enumerate(problem.probes)}

    sizes = sf.support_sizes
    material = problem.material
    out = PlasticOutput(
        method="ctm-rpim-mc", points=nodes,
        cells=[("line", conf.boundary.edges), ("triangle", conf.boundary.triangles)],
        displacement=lambda U: U.reshape(-1, 2).copy(), nodal=nodal, average=average, probe_values=probe_values,
        peak_traction=float(np.hypot(tags.tx, tags.ty).max(initial=0.0)),
        counts={"nodes": len(nodes), "integration_points": len(system.w),
                "support_size": {"min": int(sizes.min()), "mean": float(sizes.mean()), "max": int(sizes.max())}},
        parameters={**case.resolved, "derived": {"d_c": conf.lengths.d_c, "G": material.G, "K": material.K}})
    return run_elastoplastic(case, system, out, timer, progress)
