"""TOML problem files -> :class:`Case` (a Problem plus how to discretise and solve it).

Every section and key is checked: unknown keys are errors with the closest known key suggested,
missing required keys are named, and every default that was applied is recorded so that
``summary.json`` can echo the fully resolved input. Numbers may be written as expressions of the
``[parameters]`` (``"W/2"``), which are themselves evaluated in file order.
"""
from __future__ import annotations

import copy
import difflib
import math
import tomllib
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from ctmrpim.errors import ProblemError
from ctmrpim.materials.linear_elastic import LinearElastic
from ctmrpim.materials.mohr_coulomb import MohrCoulomb
from ctmrpim.materials.neo_hookean import NeoHookean
from ctmrpim.problem.case import Case
from ctmrpim.problem.expressions import Field, constant
from ctmrpim.problem.geometry import CIRCLE_SAGITTA, Geometry, Shape
from ctmrpim.problem.model import (
    NO_SLIP,
    Constraint,
    ExactSolution,
    PointLoad,
    Pressure,
    Probe,
    Problem,
    Traction,
    Wall,
)
from ctmrpim.problem.node_cloud import NodeSpec
from ctmrpim.problem.settings import Explicit, Loading, Method, Relaxation, StrengthReduction

SECTIONS: dict[str, set[str] | None] = {
    "problem": {"name", "analysis", "plane", "thickness", "description", "gravity"},
    "parameters": None,  # any names
    "geometry": {"add", "subtract"},
    "nodes": {"grid", "spacing", "file"},
    "material": {"model", "E", "nu", "density", "c", "phi", "psi", "tension"},
    "method": set(Method.__dataclass_fields__),
    "constraint": {"where", "ux", "uy"},
    "traction": {"where", "tx", "ty", "follower"},
    "pressure": {"where", "p"},
    "probe": {"name", "at"},
    "point_load": {"at", "fx", "fy"},
    "exact": {"ux", "uy", "sxx", "syy", "sxy"},
    "loading": {"steps", "tolerance", "max_iterations", "max_cutbacks", "tangent", "until_failure"},
    "strength-reduction": {"solver", "start", "step", "width", "max_srf", "steps", "values"},
    "dynamic": {"steps", "damping", "tolerance", "record_every"},
    "explicit": set(Explicit.__dataclass_fields__),
    "wall": {"name", "point", "normal", "friction", "gate"},
}
LIST_SECTIONS = {"constraint", "traction", "pressure", "probe", "point_load", "wall"}
REQUIRED = {"problem": ["name"], "geometry": ["add"], "material": ["model", "E", "nu"],
            "constraint": ["where"], "traction": ["where"], "pressure": ["where", "p"],
            "probe": ["name", "at"], "point_load": ["at"], "wall": ["name", "point", "normal"]}
#: Names people reach for instead of the file's keys, to suggest where difflib finds no close spelling.
SYNONYMS = {"youngs": "E", "young": "E", "youngs_modulus": "E", "young_modulus": "E", "modulus": "E",
            "poisson": "nu", "poissons_ratio": "nu", "poisson_ratio": "nu", "rho": "density"}
ANALYSES = ("linear", "quasi-static", "strength-reduction", "dynamic", "explicit")
MATERIAL_MODELS = ("linear-elastic", "neo-hookean", "mohr-coulomb")
#: the material models each analysis solves (quasi-static linear-elastic: the updated-Lagrangian rate form)
ANALYSIS_MODELS = {"linear": ("linear-elastic",), "quasi-static": ("neo-hookean", "linear-elastic", "mohr-coulomb"),
                   "strength-reduction": ("mohr-coulomb",), "dynamic": ("mohr-coulomb",),
                   "explicit": ("mohr-coulomb",)}


def read_case(path: str | Path, overrides: list[str] | None = None) -> Case:
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise ProblemError(f"cannot read problem file ({exc.strerror})", source=str(path)) from None
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ProblemError(f"malformed TOML: {exc}", source=str(path)) from None
    try:
        return parse_case(raw, source=str(path), base_dir=path.parent, overrides=overrides)
    except ProblemError as exc:
        raise exc.at(source=str(path)) from None


def apply_overrides(raw: dict, overrides: list[str]) -> dict:
    """``section.key=value`` settings (value in TOML syntax, else a string) applied to a raw file."""
    raw = copy.deepcopy(raw)
    for item in overrides:
        dotted, eq, value = item.partition("=")
        section, dot, key = (part.strip() for part in dotted.partition("."))
        if not (eq and dot and section and key):  # `method.=3` would otherwise set a key named ''
            raise ProblemError(f"--set {item!r}: expected section.key=value")
        if section not in SECTIONS or section in LIST_SECTIONS:
            raise ProblemError(f"--set {item!r}: can set keys of {', '.join(s for s in SECTIONS if s not in LIST_SECTIONS)}")
        try:
            parsed = tomllib.loads(f"v = {value}")["v"]
        except tomllib.TOMLDecodeError as exc:
            if value.strip()[:1] in ("[", "{", '"', "'"):  # meant as TOML: a string fallback would hide the typo
                raise ProblemError(f"--set {item!r}: the value is not valid TOML ({exc})") from None
            parsed = value.strip()
        table = raw.setdefault(section, {})
        if section == "nodes":  # grid, spacing and file exclude each other: the new one replaces
            table.clear()
        table[key] = parsed
    return raw


def parse_case(raw: dict, source: str, base_dir: Path, overrides: list[str] | None = None) -> Case:
    if overrides:
        raw = apply_overrides(raw, overrides)
    _check_keys(raw)
    defaults: list[str] = []

    def get(section: str, key: str, default: Any) -> Any:
        table = raw.get(section, {})
        if key in table:
            return table[key]
        defaults.append(f"{section}.{key} = {default!r}")
        return default

    params = _parameters(raw.get("parameters", {}))

    def num(value: Any, key: str) -> float:
        try:
            return constant(value, params)
        except ProblemError as exc:
            raise exc.at(key=key) from None

    def fld(value: Any, key: str) -> Field:
        try:
            return Field(value, params)
        except ProblemError as exc:
            raise exc.at(key=key) from None

    prob = raw.get("problem", {})
    if not isinstance(prob["name"], str) or not prob["name"].strip() or any(c in prob["name"] for c in "/\\"):
        # the name is the default output folder runs/NAME: it must be one plain folder name
        raise ProblemError(f"name = {prob['name']!r} must be a non-empty string without / or \\",
                           key="problem.name")
    analysis = get("problem", "analysis", "linear")
    if analysis not in ANALYSES:
        raise ProblemError(f"analysis {analysis!r} is not supported (supported: {', '.join(ANALYSES)})",
                           key="problem.analysis")
    plane = get("problem", "plane", "stress")
    if plane not in ("stress", "strain"):
        raise ProblemError(f"plane must be 'stress' or 'strain', not {plane!r}", key="problem.plane")
    thickness = num(get("problem", "thickness", 1.0), "problem.thickness")
    gravity_raw = get("problem", "gravity", [0.0, 0.0])
    if not isinstance(gravity_raw, list) or len(gravity_raw) != 2:
        raise ProblemError(f"{gravity_raw!r} must be [gx, gy] (an acceleration)", key="problem.gravity")
    gravity = tuple(num(v, "problem.gravity") for v in gravity_raw)
    if not thickness > 0:
        raise ProblemError(f"thickness = {thickness} must be > 0", key="problem.thickness")

    geometry = _geometry(raw.get("geometry", {}), num)

    mat = raw.get("material", {})
    if mat.get("model") not in MATERIAL_MODELS:
        raise ProblemError(f"model {mat.get('model')!r} is not supported (supported: {', '.join(MATERIAL_MODELS)})",
                           key="material.model")
    if mat["model"] not in ANALYSIS_MODELS[analysis]:
        raise ProblemError(f"analysis {analysis!r} needs model = {' or '.join(map(repr, ANALYSIS_MODELS[analysis]))}, "
                           f"not {mat['model']!r}", key="material.model")
    material = LinearElastic(E=num(mat["E"], "material.E"), nu=num(mat["nu"], "material.nu"),
                             density=num(get("material", "density", 0.0), "material.density"))
    if mat["model"] == "neo-hookean":
        material = NeoHookean(material.E, material.nu, material.density)
    elif mat["model"] == "mohr-coulomb":
        missing = [k for k in ("c", "phi") if k not in mat]
        if missing:
            raise ProblemError(f"model 'mohr-coulomb' needs {' and '.join(missing)}", key=f"material.{missing[0]}")
        tension = get("material", "tension", None)
        material = MohrCoulomb(material.E, material.nu, num(mat["c"], "material.c"), num(mat["phi"], "material.phi"),
                               num(get("material", "psi", 0.0), "material.psi"), material.density,
                               None if tension is None else num(tension, "material.tension"))
        if plane != "strain":
            raise ProblemError("the Mohr-Coulomb model is implemented in plane strain; set problem.plane = \"strain\"",
                               key="problem.plane")
    loading_raw = raw.get("loading", {})
    loading = Loading(**{k: (num(v, f"loading.{k}") if k == "tolerance" else v) for k, v in loading_raw.items()})
    sr_raw = raw.get("strength-reduction")
    if sr_raw is not None and analysis != "strength-reduction":
        raise ProblemError("[strength-reduction] needs analysis = \"strength-reduction\"", key="problem.analysis")
    def settings(cls, section: str, table: dict | None, numbers: tuple[str, ...]):
        """A settings dataclass from its table: defaults recorded, ``numbers`` read as expressions."""
        kwargs = {}
        for key, spec in cls.__dataclass_fields__.items():
            if key not in (table or {}):
                defaults.append(f"{section}.{key} = {spec.default!r}")
                continue
            v = table[key]
            if key == "values":
                if not isinstance(v, list):
                    raise ProblemError(f"{v!r} must be a list of SRF values", key=f"{section}.values")
                v = [num(e, f"{section}.values") for e in v]
            elif key in numbers:
                v = num(v, f"{section}.{key}")
            kwargs[key] = v
        return cls(**kwargs)

    strength_reduction = None
    if analysis == "strength-reduction":
        strength_reduction = settings(StrengthReduction, "strength-reduction", sr_raw,
                                      ("start", "step", "width", "max_srf"))
    dyn_raw = raw.get("dynamic")
    uses_relaxation = analysis == "dynamic" or (strength_reduction is not None
                                                and strength_reduction.solver == "dynamic-relaxation")
    if dyn_raw is not None and not uses_relaxation:
        raise ProblemError("[dynamic] needs analysis = \"dynamic\" or strength-reduction.solver = "
                           "\"dynamic-relaxation\"", key="dynamic")
    relaxation = settings(Relaxation, "dynamic", dyn_raw, ("damping", "tolerance")) if uses_relaxation else None
    ex_raw = raw.get("explicit")
    if ex_raw is not None and analysis != "explicit":
        raise ProblemError("[explicit] needs analysis = \"explicit\"", key="explicit")
    explicit = None
    if analysis == "explicit":
        if "dt" in (ex_raw or {}) and ex_raw["dt"] != "cfl":
            ex_raw = {**ex_raw, "dt": num(ex_raw["dt"], "explicit.dt")}
        explicit = settings(Explicit, "explicit", ex_raw, ("duration", "cfl", "damping", "viscosity", "rebuild_strain",
                                                           "relay_strain", "area_jump", "save_every", "rest",
                                                           "stage_damping", "stage_tolerance"))
    if raw.get("wall") and analysis != "explicit":
        raise ProblemError("[[wall]] (rigid contact) needs analysis = \"explicit\"", key="wall")
    if loading.tangent == "elastic" and mat["model"] != "mohr-coulomb":
        raise ProblemError("tangent = \"elastic\" is the Mohr-Coulomb solver's iteration; large-deformation "
                           "solvers use the consistent tangent", key="loading.tangent")
    if loading.until_failure and (mat["model"] != "mohr-coulomb" or analysis != "quasi-static"):
        raise ProblemError("until_failure needs a quasi-static Mohr-Coulomb analysis (a limit load)",
                           key="loading.until_failure")

    constraints = []
    for i, c in enumerate(raw.get("constraint", [])):
        if "ux" not in c and "uy" not in c:
            raise ProblemError("give ux, uy or both", key=f"constraint[{i}]")
        constraints.append(Constraint(where=fld(c["where"], f"constraint[{i}].where"),
                                      ux=fld(c["ux"], f"constraint[{i}].ux") if "ux" in c else None,
                                      uy=fld(c["uy"], f"constraint[{i}].uy") if "uy" in c else None))
    tractions = []
    for i, c in enumerate(raw.get("traction", [])):
        if "tx" not in c and "ty" not in c:
            raise ProblemError("give tx, ty or both", key=f"traction[{i}]")
        follower = c.get("follower", False)
        if not (isinstance(follower, bool) or follower in ("segment", "face")):   # 1 == True: test the type
            raise ProblemError(f"{follower!r} must be false, true (= \"segment\") or \"face\"",
                               key=f"traction[{i}].follower")
        turn = follower if isinstance(follower, str) else "segment"
        follower = follower is not False
        if follower and analysis == "linear":
            raise ProblemError("follower loads need a large-deformation analysis (quasi-static)",
                               key=f"traction[{i}].follower")
        tractions.append(Traction(where=fld(c["where"], f"traction[{i}].where"),
                                  tx=fld(c["tx"], f"traction[{i}].tx") if "tx" in c else None,
                                  ty=fld(c["ty"], f"traction[{i}].ty") if "ty" in c else None,
                                  follower=follower, turn=turn))
    pressures = [Pressure(where=fld(c["where"], f"pressure[{i}].where"), p=fld(c["p"], f"pressure[{i}].p"))
                 for i, c in enumerate(raw.get("pressure", []))]
    probes = []
    # a probe on a true arc lies up to the sagitta outside the circle's polygon
    probe_tol = (1e-9 * math.sqrt(geometry.area)
                 + 2.0 * CIRCLE_SAGITTA * max((c[2] for c in geometry.circles), default=0.0))
    def point(at: Any, key: str) -> tuple[float, float]:
        if not isinstance(at, list) or len(at) != 2:
            raise ProblemError(f"at = {at!r} must be [x, y]", key=key)
        x, y = num(at[0], key), num(at[1], key)
        # checked here, where the key is known: outside the body RPIM would fail later naming only a point
        if geometry.distance_outside(np.array([[x, y]]))[0] > probe_tol:
            raise ProblemError(f"({x:g}, {y:g}) lies outside the geometry", key=key)
        return x, y

    for i, c in enumerate(raw.get("probe", [])):
        probes.append(Probe(str(c["name"]), *point(c["at"], f"probe[{i}].at")))
    point_loads = []
    for i, c in enumerate(raw.get("point_load", [])):
        if "fx" not in c and "fy" not in c:
            raise ProblemError("give fx, fy or both", key=f"point_load[{i}]")
        point_loads.append(PointLoad(*point(c["at"], f"point_load[{i}].at"),
                                     fx=num(c.get("fx", 0.0), f"point_load[{i}].fx"),
                                     fy=num(c.get("fy", 0.0), f"point_load[{i}].fy")))
    names = [p.name for p in probes]
    if len(set(names)) != len(names):
        raise ProblemError(f"probe names must be unique ({names})", key="probe")
    exact = None
    if "exact" in raw:
        exact = ExactSolution(**{k: fld(v, f"exact.{k}") for k, v in raw["exact"].items()})

    walls = []
    for i, c in enumerate(raw.get("wall", [])):
        friction = c.get("friction", NO_SLIP)
        if friction != NO_SLIP:
            friction = num(friction, f"wall[{i}].friction")
        gate = c.get("gate", False)
        if not isinstance(gate, bool):
            raise ProblemError(f"{gate!r} must be true or false", key=f"wall[{i}].gate")
        vectors = []
        for k in ("point", "normal"):
            if not isinstance(c[k], list) or len(c[k]) != 2:
                raise ProblemError(f"{c[k]!r} must be [x, y]", key=f"wall[{i}].{k}")
            vectors.append(tuple(num(v, f"wall[{i}].{k}") for v in c[k]))
        try:
            walls.append(Wall(str(c["name"]), *vectors, friction=friction, gate=gate))
        except ProblemError as exc:
            raise ProblemError(exc.reason, key=f"wall[{i}]") from None
    if not constraints and not (analysis == "explicit" and walls):
        raise ProblemError("no [[constraint]]: the body is free to move rigidly", key="constraint")

    problem = Problem(name=str(prob["name"]), geometry=geometry, material=material, analysis=analysis,
                      plane=plane, thickness=thickness, gravity=gravity, parameters=params, constraints=constraints,
                      tractions=tractions, pressures=pressures, probes=probes, exact=exact,
                      point_loads=point_loads, walls=walls)

    nodes_raw = raw.get("nodes")
    if not nodes_raw:
        raise ProblemError("missing section [nodes] (grid = [nx, ny], spacing = h or file = ...)", key="nodes")
    nodes = NodeSpec(grid=_grid(nodes_raw["grid"], num) if "grid" in nodes_raw else None,
                     spacing=num(nodes_raw["spacing"], "nodes.spacing") if "spacing" in nodes_raw else None,
                     file=str(nodes_raw["file"]) if "file" in nodes_raw else None)

    method_raw = dict(raw.get("method", {}))
    kwargs: dict[str, Any] = {}
    for key, spec in Method.__dataclass_fields__.items():
        if key not in method_raw:
            defaults.append(f"method.{key} = {spec.default!r}")
            continue
        v = method_raw[key]
        if key == "line_spacing":
            if not isinstance(v, list) or len(v) != 2:
                raise ProblemError(f"{v!r} must be [r_x, r_y]", key="method.line_spacing")
            v = tuple(num(e, "method.line_spacing") for e in v)
        elif key in ("support_radius", "eta", "alpha", "match_tolerance", "point_regeneration"):
            v = num(v, f"method.{key}")
        elif key == "gauss_points" and (isinstance(v, bool) or not isinstance(v, int)):
            raise ProblemError(f"{v!r} must be an integer", key="method.gauss_points")
        kwargs[key] = v
    method = Method(**kwargs)
    if analysis == "quasi-static" and mat["model"] == "linear-elastic" and method.formulation == "total-lagrangian":
        raise ProblemError("the total-Lagrangian formulation needs model = 'neo-hookean' (a linear-elastic "
                           "material at large deformation is a rate law: method.formulation = "
                           "\"updated-lagrangian\")", key="material.model")

    resolved = {
        "problem": {"name": problem.name, "analysis": analysis, "plane": plane, "thickness": thickness,
                    "gravity": list(gravity)},
        "parameters": params,
        # the shapes with their expressions evaluated ("-W/2" -> -6.0), as the solver saw them
        "geometry": {k: [{sh.kind: [list(v) if isinstance(v, tuple) else v for v in sh.data]} for sh in shapes]
                     for k, shapes in (("add", geometry.add), ("subtract", geometry.subtract))},
        "nodes": nodes.as_dict(),
        "material": {"model": mat["model"], "E": material.E, "nu": material.nu, "density": material.density,
                     **({"c": material.c, "phi": material.phi, "psi": material.psi, "tension": material.tension}
                        if isinstance(material, MohrCoulomb) else {})},
        "method": method.as_dict(),
        "constraint": [{k: str(v) for k, v in c.items()} for c in raw.get("constraint", [])],
        "traction": [{k: str(v) for k, v in c.items()} for c in raw.get("traction", [])],
        "pressure": [{k: str(v) for k, v in c.items()} for c in raw.get("pressure", [])],
        "probe": [{"name": p.name, "at": [p.x, p.y]} for p in probes],
        "point_load": [{"at": [p.x, p.y], "fx": p.fx, "fy": p.fy} for p in point_loads],
        "exact": {k: str(v) for k, v in raw.get("exact", {}).items()},
    }
    if analysis in ("quasi-static", "strength-reduction"):
        resolved["loading"] = asdict(loading)
    if relaxation is not None:
        resolved["dynamic"] = asdict(relaxation)
    if explicit is not None:
        resolved["explicit"] = asdict(explicit)
        resolved["wall"] = [asdict(w) for w in walls]
    if strength_reduction is not None:
        resolved["strength-reduction"] = {**asdict(strength_reduction), "values": list(strength_reduction.values)}
    return Case(problem=problem, nodes=nodes, method=method, source=source, base_dir=base_dir,
                resolved=resolved, defaults=defaults, loading=loading, strength_reduction=strength_reduction,
                relaxation=relaxation, explicit=explicit)


def _grid(value: Any, num) -> tuple[int, int]:
    if not isinstance(value, list) or len(value) != 2:
        raise ProblemError(f"{value!r} must be [nx, ny]", key="nodes.grid")
    n = [num(v, "nodes.grid") for v in value]
    if not all(float(v).is_integer() for v in n):
        raise ProblemError(f"{value!r} must be two integers", key="nodes.grid")
    return int(n[0]), int(n[1])


def _check_keys(raw: dict) -> None:
    for section, value in raw.items():
        if section not in SECTIONS:
            raise ProblemError(f"unknown section [{section}]{_suggest(section, SECTIONS)}")
        allowed = SECTIONS[section]
        entries = value if section in LIST_SECTIONS else [value]
        if section in LIST_SECTIONS and not isinstance(value, list):
            raise ProblemError(f"write it as [[{section}]] (a list of tables)", key=section)
        for i, entry in enumerate(entries):
            where = f"{section}[{i}]" if section in LIST_SECTIONS else section
            if not isinstance(entry, dict):
                raise ProblemError(f"expected a table, got {entry!r}", key=where)
            if allowed is not None:
                for key in entry:
                    if key not in allowed:
                        raise ProblemError(f"unknown key{_suggest(key, allowed)}", key=f"{where}.{key}")
            for key in REQUIRED.get(section, []):
                if key not in entry:
                    raise ProblemError("missing required key", key=f"{where}.{key}")
    for section in ("problem", "geometry", "material"):
        if section not in raw:
            raise ProblemError(f"missing section [{section}]")


def _suggest(word: str, options) -> str:
    """`` (did you mean 'x'?)`` for the closest option: a known synonym (``youngs`` -> ``E``), a
    different capitalisation (``e`` -> ``E``), or the closest spelling."""
    options = list(options)
    lower = {o.lower(): o for o in options}
    if SYNONYMS.get(word.lower()) in options:
        close = [SYNONYMS[word.lower()]]
    elif word.lower() in lower:
        close = [lower[word.lower()]]
    else:
        close = difflib.get_close_matches(word, options, n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _parameters(table: dict) -> dict[str, float]:
    params: dict[str, float] = {}
    for name, value in table.items():
        if not name.isidentifier():
            raise ProblemError(f"{name!r} is not a valid name", key=f"parameters.{name}")
        if name in ("x", "y", "t"):
            raise ProblemError(f"{name!r} is reserved for the coordinates and time", key=f"parameters.{name}")
        try:
            params[name] = constant(value, params)
        except ProblemError as exc:
            raise exc.at(key=f"parameters.{name}") from None
    return params


def _geometry(table: dict, num) -> Geometry:
    def shapes(key: str) -> list[Shape]:
        items = table.get(key, [])
        if not isinstance(items, list):
            raise ProblemError("must be a list of shapes", key=f"geometry.{key}")
        out = []
        for i, item in enumerate(items):
            where = f"geometry.{key}[{i}]"
            if not isinstance(item, dict) or len(item) != 1:
                raise ProblemError("each shape is one of {rectangle = [...]}, {polygon = [...]}, {circle = [...]}",
                                   key=where)
            kind, data = next(iter(item.items()))
            try:
                if kind in ("rectangle", "circle"):
                    n = 4 if kind == "rectangle" else 3
                    if not isinstance(data, list) or len(data) != n:
                        raise ProblemError(f"{kind} needs {n} numbers")
                    out.append(Shape(kind, tuple(num(v, where) for v in data)))
                elif kind == "polygon":
                    if not isinstance(data, list) or not all(isinstance(p, list) and len(p) == 2 for p in data):
                        raise ProblemError("polygon needs a list of [x, y] vertices")
                    out.append(Shape(kind, tuple((num(p[0], where), num(p[1], where)) for p in data)))
                else:
                    raise ProblemError(f"unknown shape {kind!r}{_suggest(kind, ['rectangle', 'polygon', 'circle'])}")
                out[-1].polygon()  # validates
            except ProblemError as exc:
                raise exc.at(key=where) from None
        return out

    try:
        return Geometry(add=shapes("add"), subtract=shapes("subtract"))
    except ProblemError as exc:
        raise exc.at(key="geometry") from None
