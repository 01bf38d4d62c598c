"""The fully resolved input (every default applied, every expression evaluated) that ``summary.json`` echoes."""
from __future__ import annotations

from dataclasses import asdict
from typing import Any

from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.problem.model import Problem
from ctmrpim.problem.node_cloud import NodeSpec
from ctmrpim.problem.reader.settings import Solving
from ctmrpim.problem.settings import Method


def resolve(raw: dict, problem: Problem, nodes: NodeSpec, method: Method, solving: Solving) -> dict[str, Any]:
    """The input as the solver saw it; the sections of other analyses are left out."""
    geometry, material = problem.geometry, problem.material
    resolved = {
        "problem": {"name": problem.name, "analysis": problem.analysis, "plane": problem.plane,
                    "thickness": problem.thickness, "gravity": list(problem.gravity)},
        "parameters": problem.parameters,
        # the shapes with their expressions evaluated ("-W/2" -> -6.0), as the solver saw them
        "geometry": {k: [{sh.kind: [list(v) if isinstance(v, tuple) else v for v in sh.data]} for sh in shapes]
                     for k, shapes in (("add", geometry.add), ("subtract", geometry.subtract))},
        "nodes": nodes.as_dict(),
        "material": {"model": raw["material"]["model"], "E": material.E, "nu": material.nu,
                     "density": material.density,
                     **({"c": material.c, "phi": material.phi, "psi": material.psi, "tension": material.tension}
                        if isinstance(material, MohrCoulomb) else {})},
        "method": method.as_dict(),
        # boundary conditions as written: their expressions are of x and y, kept as text
        "constraint": [{k: str(v) for k, v in c.items()} for c in raw.get("constraint", [])],
        "traction": [{k: str(v) for k, v in c.items()} for c in raw.get("traction", [])],
        "pressure": [{k: str(v) for k, v in c.items()} for c in raw.get("pressure", [])],
        "probe": [{"name": p.name, "at": [p.x, p.y]} for p in problem.probes],
        "point_load": [{"at": [p.x, p.y], "fx": p.fx, "fy": p.fy} for p in problem.point_loads],
        "exact": {k: str(v) for k, v in raw.get("exact", {}).items()},
    }
    if problem.body_load is not None:
        resolved["body-force"] = {"bx": problem.body_load.bx.text, "by": problem.body_load.by.text}
    if problem.analysis in ("quasi-static", "strength-reduction"):
        resolved["loading"] = asdict(solving.loading)
    if solving.relaxation is not None:
        resolved["dynamic"] = asdict(solving.relaxation)
    if solving.explicit is not None:
        resolved["explicit"] = asdict(solving.explicit)
        resolved["wall"] = [asdict(w) for w in problem.walls]
    if solving.strength_reduction is not None:
        resolved["strength-reduction"] = {**asdict(solving.strength_reduction),
                                          "values": list(solving.strength_reduction.values)}
    return resolved
