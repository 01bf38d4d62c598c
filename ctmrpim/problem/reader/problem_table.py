"""The ``[problem]`` table: name, analysis, plane, thickness and gravity."""
from __future__ import annotations

from dataclasses import dataclass

from ctmrpim.errors import ProblemError
from ctmrpim.problem.reader.values import Values

ANALYSES = ("linear", "quasi-static", "strength-reduction", "dynamic", "explicit")


@dataclass(frozen=True)
class ProblemTable:
    """The ``[problem]`` table, checked, with its defaults applied."""

    name: str
    analysis: str
    plane: str
    thickness: float
    gravity: tuple[float, float]


def read_problem_table(values: Values) -> ProblemTable:
    """The ``[problem]`` table; ``values`` records the defaults applied."""
    name = values.raw.get("problem", {})["name"]
    if not isinstance(name, str) or not name.strip() or any(c in name for c in "/\\"):
        # a benchmark's default output folder is runs/NAME: the name must be one plain folder name
        raise ProblemError(f"name = {name!r} must be a non-empty string without / or \\", key="problem.name")
    analysis = values.get("problem", "analysis", "linear")
    if analysis not in ANALYSES:
        raise ProblemError(f"analysis {analysis!r} is not supported (supported: {', '.join(ANALYSES)})",
                           key="problem.analysis")
    plane = values.get("problem", "plane", "stress")
    if plane not in ("stress", "strain"):
        raise ProblemError(f"plane must be 'stress' or 'strain', not {plane!r}", key="problem.plane")
    thickness = values.number(values.get("problem", "thickness", 1.0), "problem.thickness")
    gravity_raw = values.get("problem", "gravity", [0.0, 0.0])
    if not isinstance(gravity_raw, list) or len(gravity_raw) != 2:
        raise ProblemError(f"{gravity_raw!r} must be [gx, gy] (an acceleration)", key="problem.gravity")
    gravity = tuple(values.number(v, "problem.gravity") for v in gravity_raw)
    if not thickness > 0:
        raise ProblemError(f"thickness = {thickness} must be > 0", key="problem.thickness")
    return ProblemTable(name=name, analysis=analysis, plane=plane, thickness=thickness, gravity=gravity)
