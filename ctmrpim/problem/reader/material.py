"""The ``[material]`` table: the constitutive model and its constants."""
from __future__ import annotations

from ctmrpim.errors import ProblemError
from ctmrpim.materials.linear_elastic import LinearElastic
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.materials.neo_hookean import NeoHookean
from ctmrpim.problem.reader.problem_table import ProblemTable
from ctmrpim.problem.reader.values import Values

MATERIAL_MODELS = ("linear-elastic", "neo-hookean", "mohr-coulomb")
#: the material models each analysis solves (quasi-static linear-elastic: the updated-Lagrangian rate form)
ANALYSIS_MODELS = {"linear": ("linear-elastic",), "quasi-static": ("neo-hookean", "linear-elastic", "mohr-coulomb"),
                   "strength-reduction": ("mohr-coulomb",), "dynamic": ("mohr-coulomb",),
                   "explicit": ("mohr-coulomb",)}


def read_material(problem: ProblemTable, values: Values) -> LinearElastic | NeoHookean | MohrCoulomb:
    """The material of ``[material]``, checked against the analysis and plane of ``[problem]``."""
    mat = values.raw.get("material", {})
    if mat.get("model") not in MATERIAL_MODELS:
        raise ProblemError(f"model {mat.get('model')!r} is not supported (supported: {', '.join(MATERIAL_MODELS)})",
                           key="material.model")
    analysis = problem.analysis
    if mat["model"] not in ANALYSIS_MODELS[analysis]:
        raise ProblemError(f"analysis {analysis!r} needs model = {' or '.join(map(repr, ANALYSIS_MODELS[analysis]))}, "
                           f"not {mat['model']!r}", key="material.model")
    material = LinearElastic(E=values.number(mat["E"], "material.E"), nu=values.number(mat["nu"], "material.nu"),
                             density=values.number(values.get("material", "density", 0.0), "material.density"))
    if mat["model"] == "neo-hookean":
        return NeoHookean(material.E, material.nu, material.density)
    if mat["model"] == "mohr-coulomb":
        return _mohr_coulomb(mat, material, problem.plane, values)
    return material


def _mohr_coulomb(mat: dict, elastic: LinearElastic, plane: str, values: Values) -> MohrCoulomb:
    missing = [k for k in ("c", "phi") if k not in mat]
    if missing:
        raise ProblemError(f"model 'mohr-coulomb' needs {' and '.join(missing)}", key=f"material.{missing[0]}")
    tension = values.get("material", "tension", None)
    material = MohrCoulomb(elastic.E, elastic.nu, values.number(mat["c"], "material.c"),
                           values.number(mat["phi"], "material.phi"),
                           values.number(values.get("material", "psi", 0.0), "material.psi"), elastic.density,
                           None if tension is None else values.number(tension, "material.tension"))
    if plane != "strain":
        raise ProblemError("the Mohr-Coulomb model is implemented in plane strain; set problem.plane = \"strain\"",
                           key="problem.plane")
    return material
