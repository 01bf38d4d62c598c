"""The settings tables: ``[loading]``, ``[strength-reduction]``, ``[dynamic]``, ``[explicit]`` and ``[method]``.

Each is read by one generic reader into its dataclass of :mod:`ctmrpim.problem.settings`, which then
validates itself: the ``float`` fields are read as expressions of the parameters, the lists below as
lists of them, and every default applied is recorded. This module also holds the rules that tie a
table to the analysis or the material (``[explicit]`` needs ``analysis = "explicit"``, ...).
"""
from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, TypeVar, get_type_hints

from ctmrpim.errors import ProblemError
from ctmrpim.problem.reader.values import Values
from ctmrpim.problem.settings import DEFAULT_INTEGRATION, Explicit, Loading, Method, Relaxation, StrengthReduction

T = TypeVar("T")

#: settings written as lists of numbers: ``section.key`` -> (length, None for any; what the list must be)
LISTS = {"method.line_spacing": (2, "[r_x, r_y]"), "strength-reduction.values": (None, "a list of SRF values")}
#: settings that must be written as integers (not 2.0, not true)
INTEGERS = {"method.gauss_points"}


@dataclass(frozen=True)
class Solving:
    """The solver settings of an analysis; those it does not use are None."""

    loading: Loading
    strength_reduction: StrengthReduction | None
    relaxation: Relaxation | None
    explicit: Explicit | None


def read_settings(cls: type[T], section: str, table: dict | None, values: Values, *,
                  record_defaults: bool = True, defaults: dict[str, Any] | None = None) -> T:
    """The settings dataclass ``cls`` from its ``table``: its numbers read as expressions, the
    defaults of the keys not given (the dataclass's, or those of ``defaults`` where it has the key)
    applied and recorded in ``values`` (unless ``record_defaults`` is false)."""
    table = table or {}
    defaults = defaults or {}
    hints = get_type_hints(cls)
    kwargs: dict[str, Any] = {}
    for spec in fields(cls):
        key, where = spec.name, f"{section}.{spec.name}"
        if key not in table:
            if key in defaults:
                kwargs[key] = defaults[key]
            if record_defaults:
                values.record(section, key, defaults.get(key, spec.default))
            continue
        value = table[key]
        if where in LISTS:
            length, shape = LISTS[where]
            if not isinstance(value, list) or (length is not None and len(value) != length):
                raise ProblemError(f"{value!r} must be {shape}", key=where)
            value = tuple(values.number(e, where) for e in value)
        elif where in INTEGERS and (isinstance(value, bool) or not isinstance(value, int)):
            raise ProblemError(f"{value!r} must be an integer", key=where)
        elif hints[key] is float:
            value = values.number(value, where)
        kwargs[key] = value
    return cls(**kwargs)


def read_solving(analysis: str, values: Values) -> Solving:
    """``[loading]`` and the tables of the analysis' solver; a table the analysis does not use is an error."""
    raw = values.raw
    # [loading]'s defaults were never listed in `defaults`: recording them now would change summary.json
    loading = read_settings(Loading, "loading", raw.get("loading"), values, record_defaults=False)
    if raw.get("strength-reduction") is not None and analysis != "strength-reduction":
        raise ProblemError("[strength-reduction] needs analysis = \"strength-reduction\"", key="problem.analysis")
    strength_reduction = None
    if analysis == "strength-reduction":
        strength_reduction = read_settings(StrengthReduction, "strength-reduction", raw.get("strength-reduction"),
                                           values)
    uses_relaxation = analysis == "dynamic" or (strength_reduction is not None
                                                and strength_reduction.solver == "dynamic-relaxation")
    if raw.get("dynamic") is not None and not uses_relaxation:
        raise ProblemError("[dynamic] needs analysis = \"dynamic\" or strength-reduction.solver = "
                           "\"dynamic-relaxation\"", key="dynamic")
    relaxation = read_settings(Relaxation, "dynamic", raw.get("dynamic"), values) if uses_relaxation else None
    explicit_raw = raw.get("explicit")
    if explicit_raw is not None and analysis != "explicit":
        raise ProblemError("[explicit] needs analysis = \"explicit\"", key="explicit")
    explicit = None
    if analysis == "explicit":
        # dt is a time step or the word "cfl" (one from the stability limit): a number only when not the word
        if "dt" in (explicit_raw or {}) and explicit_raw["dt"] != "cfl":
            explicit_raw = {**explicit_raw, "dt": values.number(explicit_raw["dt"], "explicit.dt")}
        explicit = read_settings(Explicit, "explicit", explicit_raw, values)
    return Solving(loading=loading, strength_reduction=strength_reduction, relaxation=relaxation, explicit=explicit)


def check_loading(loading: Loading, model: str, analysis: str) -> None:
    """Raise if ``[loading]`` asks for what only the Mohr-Coulomb solvers do."""
    if loading.tangent == "elastic" and model != "mohr-coulomb":
        raise ProblemError("tangent = \"elastic\" is the Mohr-Coulomb solver's iteration; large-deformation "
                           "solvers use the consistent tangent", key="loading.tangent")
    if loading.until_failure and (model != "mohr-coulomb" or analysis != "quasi-static"):
        raise ProblemError("until_failure needs a quasi-static Mohr-Coulomb analysis (a limit load)",
                           key="loading.until_failure")


def read_method(values: Values, model: str, analysis: str) -> Method:
    """The ``[method]`` table, checked against the material model and the analysis."""
    method = read_settings(Method, "method", values.raw.get("method"), values,
                           defaults={"integration": DEFAULT_INTEGRATION.get(analysis, "ctm")})
    if analysis == "quasi-static" and model == "linear-elastic" and method.formulation == "total-lagrangian":
        raise ProblemError("the total-Lagrangian formulation needs model = 'neo-hookean' (a linear-elastic "
                           "material at large deformation is a rate law: method.formulation = "
                           "\"updated-lagrangian\")", key="material.model")
    return method
