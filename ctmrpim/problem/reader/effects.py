"""Settings that would be silently without effect: refused with one line, or warned about where the
setting is harmless and common (a density in a problem without gravity).

The rule: nothing the user wrote is silently without effect. The checks here need the whole file
(a key's effect depends on the analysis and the material model); those that need the nodes
(conflicting constraints, a load on a constrained edge, too few supports) are made where the
selectors are evaluated (:mod:`ctmrpim.discretisation.boundary_conditions`). Those that need the method
chosen on the command line (CTM-RPIM's ``[method]`` keys under ``--solver fem``) are
:func:`check_solver_effects`, which the command line calls.
"""
from __future__ import annotations

import warnings
from collections.abc import Iterable

from ctmrpim.errors import ProblemError
from ctmrpim.problem.reader.problem_table import ProblemTable
from ctmrpim.problem.settings import Method

#: [material] keys only the Mohr-Coulomb model reads
MOHR_COULOMB_KEYS = ("c", "phi", "psi", "tension")
#: analyses that read [loading] (Newton's load stepping; strength reduction's levels)
LOADING_ANALYSES = ("quasi-static", "strength-reduction")
#: analyses in which the density only enters through gravity (no inertia)
STATIC_ANALYSES = ("linear", "quasi-static")
#: per method other than CTM-RPIM: how a message names its solve, and the only [method] keys it reads (the
#: finite elements: the '==' tolerance of the `where` selectors); a method not named here reads them all
METHOD_KEYS_READ = {"fem": ("the finite-element solve", ("match_tolerance",)),
                    "fenicsx": ("the FEniCSx solve", ("match_tolerance",))}


def check_effects(raw: dict, table: ProblemTable, model: str, density: float) -> None:
    """Raise (or warn) for a setting of the parsed file ``raw`` that would have no effect in its analysis
    (``table``) with its material ``model`` and ``density``."""
    analysis = table.analysis
    material = raw.get("material", {})
    for key in MOHR_COULOMB_KEYS:
        if key in material and model != "mohr-coulomb":
            raise ProblemError(f"{key} is read only by model = \"mohr-coulomb\", not by {model!r}: remove it",
                               key=f"material.{key}")
    if "loading" in raw and analysis not in LOADING_ANALYSES:
        raise ProblemError(f"[loading] has no effect in a {analysis!r} analysis (it steps the loads of "
                           "\"quasi-static\" and \"strength-reduction\" analyses): remove it", key="loading")
    if any(table.gravity):
        if density == 0:
            raise ProblemError(f"gravity = {list(table.gravity)} has no effect with material.density = 0 (the body "
                               "force is density x gravity): set material.density", key="material.density")
        if analysis == "quasi-static" and model != "mohr-coulomb":
            raise ProblemError("gravity is not in the large-deformation solvers (a Mohr-Coulomb or linear analysis "
                               "takes it): remove problem.gravity", key="problem.gravity")
    elif "density" in material and density != 0 and analysis in STATIC_ANALYSES:
        warnings.warn(f"material.density = {density:g} has no effect in a {analysis} analysis without "
                      "problem.gravity", UserWarning, stacklevel=2)
    exact = raw.get("exact")
    if exact is not None:
        if analysis != "linear":
            # a benchmark keeps its exact solution when an analysis is switched by --set (the tests compare
            # a relaxed or stepped solution with it themselves): say it, do not refuse it
            warnings.warn(f"[exact] is not compared in a {analysis!r} analysis (only linear analyses report "
                          "errors)", UserWarning, stacklevel=2)
        for group, what in ((("ux", "uy"), "the displacement (L2 error, probes)"),
                            (("sxx", "syy", "sxy"), "the stress (energy error)")):
            given = [k for k in group if k in exact]
            if given and len(given) < len(group):
                missing = [k for k in group if k not in exact]
                raise ProblemError(f"{' and '.join(missing)} missing: {what} is compared only when "
                                   f"{', '.join(group[:-1])} and {group[-1]} are all given", key="exact")


def check_method_effects(raw: dict, analysis: str, model: str, method: Method) -> None:
    """Raise for a ``[method]`` key given in ``raw`` that the solver path of ``analysis`` and ``model`` does not
    read (the path's own keys: large deformation, explicit dynamics, the consistent integration)."""
    given = raw.get("method", {})
    large_deformation = analysis == "quasi-static" and model != "mohr-coulomb"
    readers = {
        "formulation": (large_deformation, "a quasi-static analysis of a neo-Hookean or linear-elastic body"),
        "point_regeneration": (large_deformation and method.formulation == "updated-lagrangian",
                               "the updated-Lagrangian formulation"),
        "min_support": (analysis == "explicit", "explicit dynamics"),
        "correction": (method.integration == "ctm-vci", "integration = \"ctm-vci\""),
    }
    for key, (read, by) in readers.items():
        if key in given and not read:
            raise ProblemError(f"{key} is read only by {by}: it has no effect here, remove it", key=f"method.{key}")


def given_keys(section: str, resolved: dict, defaults: Iterable[str]) -> list[str]:
    """The keys of ``section`` the user wrote (in the file or with ``--set``): those of the resolved input
    ``resolved`` without an entry ``"section.key = value"`` in the ``defaults`` that were applied."""
    defaulted = {d.split(" = ", 1)[0] for d in defaults}
    return [k for k in resolved.get(section, {}) if f"{section}.{k}" not in defaulted]


def check_solver_effects(given: Iterable[str], typed: Iterable[str], solver: str) -> None:
    """``[method]`` keys that the method ``solver`` does not read: refused where they were ``typed`` with
    ``--set`` for this run (the user asked for them now), warned about in one line where the file ``given``
    them (every benchmark carries CTM-RPIM's [method] table, and its finite-element solve must still run)."""
    if solver not in METHOD_KEYS_READ:
        return
    what, read = METHOD_KEYS_READ[solver]
    only = f"--solver {solver} reads only {', '.join(f'method.{k}' for k in read)} of [method]"
    typed_unread = [k for k in dict.fromkeys(typed) if k not in read]
    if typed_unread:
        names = ", ".join(f"method.{k}" for k in typed_unread)
        remove = f"--set {names}=..." if len(typed_unread) == 1 else "those --set"
        raise ProblemError(f"{names} {_have(typed_unread)} no effect on {what} ({only}): remove {remove}",
                           key="--set")
    unread = [k for k in given if k not in read]
    if unread:
        warnings.warn(f"[method] {', '.join(unread)} {_have(unread)} no effect on {what} ({only})", UserWarning,
                      stacklevel=2)


def _have(keys: list[str]) -> str:
    return "has" if len(keys) == 1 else "have"
