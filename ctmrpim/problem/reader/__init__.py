"""TOML problem files -> :class:`Case` (a Problem plus how to discretise and solve it).

Every section and key is checked: unknown keys are errors with the closest known key suggested,
missing required keys are named, and every default that was applied is recorded so that
``summary.json`` can echo the fully resolved input. Numbers may be written as expressions of the
``[parameters]`` (``"W/2"``), which are themselves evaluated in file order.
"""
from __future__ import annotations

import tomllib
from pathlib import Path

from ctmrpim.errors import ProblemError
from ctmrpim.problem.case import Case
from ctmrpim.problem.model import Problem
from ctmrpim.problem.reader.boundary import read_body_force, read_boundary
from ctmrpim.problem.reader.effects import check_effects, check_method_effects
from ctmrpim.problem.reader.geometry import read_geometry
from ctmrpim.problem.reader.keys import check_keys
from ctmrpim.problem.reader.material import read_material
from ctmrpim.problem.reader.nodes import read_nodes
from ctmrpim.problem.reader.overrides import apply_overrides
from ctmrpim.problem.reader.problem_table import read_problem_table
from ctmrpim.problem.reader.resolved import resolve
from ctmrpim.problem.reader.settings import check_loading, read_method, read_solving
from ctmrpim.problem.reader.values import Values, read_parameters
from ctmrpim.problem.reader.walls import check_walls_allowed, read_walls

__all__ = ["apply_overrides", "parse_case", "read_case"]


def read_case(path: str | Path, overrides: list[str] | None = None) -> Case:
    """The case of the problem file at ``path``, with ``--set`` ``overrides`` applied; errors name the file."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ProblemError(f"cannot read problem file ({exc.strerror})", source=str(path)) from None
    try:
        text = data.decode("utf-8")   # TOML is UTF-8 by definition, whatever the locale says
    except UnicodeDecodeError as exc:
        bom = " (it starts with a UTF-16 byte-order mark)" if data[:2] in (b"\xff\xfe", b"\xfe\xff") else ""
        line = data[:exc.start].count(b"\n") + 1
        raise ProblemError(f"not UTF-8 text{bom}: byte 0x{data[exc.start]:02x} on line {line}; TOML files are "
                           "UTF-8, save it as UTF-8", source=str(path)) from None
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ProblemError(f"malformed TOML: {exc}", source=str(path)) from None
    try:
        return parse_case(raw, source=str(path), base_dir=path.parent, overrides=overrides)
    except ProblemError as exc:
        raise exc.at(source=str(path)) from None


def parse_case(raw: dict, source: str, base_dir: Path, overrides: list[str] | None = None) -> Case:
    """The case of a parsed problem file ``raw`` (``source`` names it, relative paths start at ``base_dir``).

    The sections are read in a fixed order, and the first mistake found is the one reported.
    """
    if overrides:
        raw = apply_overrides(raw, overrides)
    check_keys(raw)
    values = Values(raw, read_parameters(raw.get("parameters", {})))
    table = read_problem_table(values)
    analysis = table.analysis
    geometry = read_geometry(raw.get("geometry", {}), values)
    material = read_material(table, values)
    model = raw["material"]["model"]
    solving = read_solving(analysis, values)
    check_walls_allowed(raw, analysis)
    check_loading(solving.loading, model, analysis)
    boundary = read_boundary(geometry, analysis, values)
    check_effects(raw, table, model, material.density)
    walls = read_walls(values)
    if not boundary.constraints and not (analysis == "explicit" and walls):
        raise ProblemError("no [[constraint]]: the body is free to move rigidly", key="constraint")

    body_load = read_body_force(raw.get("body-force"), analysis, values)
    problem = Problem(name=table.name, geometry=geometry, material=material, analysis=analysis,
                      plane=table.plane, thickness=table.thickness, gravity=table.gravity,
                      parameters=values.parameters, constraints=boundary.constraints, tractions=boundary.tractions,
                      pressures=boundary.pressures, probes=boundary.probes, exact=boundary.exact,
                      point_loads=boundary.point_loads, walls=walls, body_load=body_load)
    nodes = read_nodes(values)
    method = read_method(values, model, analysis)
    check_method_effects(raw, analysis, model, method)
    return Case(problem=problem, nodes=nodes, method=method, source=source, base_dir=base_dir,
                resolved=resolve(raw, problem, nodes, method, solving), defaults=values.defaults,
                loading=solving.loading, strength_reduction=solving.strength_reduction,
                relaxation=solving.relaxation, explicit=solving.explicit)
