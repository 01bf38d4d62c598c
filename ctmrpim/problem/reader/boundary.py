"""The boundary conditions and point quantities: ``[[constraint]]``, ``[[traction]]``, ``[[pressure]]``,
``[[probe]]``, ``[[point_load]]``, ``[exact]`` and ``[body-force]``."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ctmrpim.errors import ProblemError
from ctmrpim.problem.geometry import CIRCLE_SAGITTA, Geometry
from ctmrpim.problem.model import BodyForce, Constraint, ExactSolution, PointLoad, Pressure, Probe, Traction
from ctmrpim.problem.reader.values import Values


@dataclass(frozen=True)
class Boundary:
    """What acts on the body and where it is observed, as the file gives them."""

    constraints: list[Constraint]
    tractions: list[Traction]
    pressures: list[Pressure]
    probes: list[Probe]
    point_loads: list[PointLoad]
    exact: ExactSolution | None


def read_boundary(geometry: Geometry, analysis: str, values: Values) -> Boundary:
    """The list sections in this order (the first error found is the one reported), then ``[exact]``."""
    raw = values.raw
    constraints = [_constraint(c, f"constraint[{i}]", values) for i, c in enumerate(raw.get("constraint", []))]
    tractions = [_traction(c, f"traction[{i}]", analysis, values) for i, c in enumerate(raw.get("traction", []))]
    pressures = [Pressure(where=values.field(c["where"], f"pressure[{i}].where"),
                          p=values.field(c["p"], f"pressure[{i}].p"))
                 for i, c in enumerate(raw.get("pressure", []))]
    inside = _Inside(geometry, values)
    probes = [Probe(str(c["name"]), *inside.point(c["at"], f"probe[{i}].at"))
              for i, c in enumerate(raw.get("probe", []))]
    point_loads = [_point_load(c, f"point_load[{i}]", inside, values) for i, c in enumerate(raw.get("point_load", []))]
    names = [p.name for p in probes]
    if len(set(names)) != len(names):
        raise ProblemError(f"probe names must be unique ({names})", key="probe")
    exact = None
    if "exact" in raw:
        exact = ExactSolution(**{k: values.field(v, f"exact.{k}") for k, v in raw["exact"].items()})
    return Boundary(constraints=constraints, tractions=tractions, pressures=pressures, probes=probes,
                    point_loads=point_loads, exact=exact)


def _constraint(c: dict, where: str, values: Values) -> Constraint:
    if "ux" not in c and "uy" not in c:
        raise ProblemError("give ux, uy or both", key=where)
    return Constraint(where=values.field(c["where"], f"{where}.where"),
                      ux=values.field(c["ux"], f"{where}.ux") if "ux" in c else None,
                      uy=values.field(c["uy"], f"{where}.uy") if "uy" in c else None)


def _traction(c: dict, where: str, analysis: str, values: Values) -> Traction:
    if "tx" not in c and "ty" not in c:
        raise ProblemError("give tx, ty or both", key=where)
    follower = c.get("follower", False)
    if not (isinstance(follower, bool) or follower in ("segment", "face")):   # 1 == True: test the type
        raise ProblemError(f"{follower!r} must be false, true (= \"segment\") or \"face\"", key=f"{where}.follower")
    turn = follower if isinstance(follower, str) else "segment"
    follower = follower is not False
    if follower and analysis == "linear":
        raise ProblemError("follower loads need a large-deformation analysis (quasi-static)", key=f"{where}.follower")
    return Traction(where=values.field(c["where"], f"{where}.where"),
                    tx=values.field(c["tx"], f"{where}.tx") if "tx" in c else None,
                    ty=values.field(c["ty"], f"{where}.ty") if "ty" in c else None,
                    follower=follower, turn=turn)


def _point_load(c: dict, where: str, inside: _Inside, values: Values) -> PointLoad:
    if "fx" not in c and "fy" not in c:
        raise ProblemError("give fx, fy or both", key=where)
    return PointLoad(*inside.point(c["at"], f"{where}.at"), fx=values.number(c.get("fx", 0.0), f"{where}.fx"),
                     fy=values.number(c.get("fy", 0.0), f"{where}.fy"))


class _Inside:
    """Points ``at = [x, y]`` that must lie in the body."""

    def __init__(self, geometry: Geometry, values: Values) -> None:
        self.geometry = geometry
        self.values = values
        # a point on a true arc lies up to the sagitta outside the circle's polygon
        self.tolerance = (1e-9 * math.sqrt(geometry.area)
                          + 2.0 * CIRCLE_SAGITTA * max((c[2] for c in geometry.circles), default=0.0))

    def point(self, at: Any, key: str) -> tuple[float, float]:
        """``at`` as (x, y), checked to lie in the body; errors name ``key``."""
        if not isinstance(at, list) or len(at) != 2:
            raise ProblemError(f"at = {at!r} must be [x, y]", key=key)
        x, y = self.values.number(at[0], key), self.values.number(at[1], key)
        # checked here, where the key is known: outside the body RPIM would fail later naming only a point
        if self.geometry.distance_outside(np.array([[x, y]]))[0] > self.tolerance:
            raise ProblemError(f"({x:g}, {y:g}) lies outside the geometry", key=key)
        return x, y


def read_body_force(table: dict | None, analysis: str, values: Values) -> BodyForce | None:
    """The ``[body-force]`` table: bx and by as expressions of x and y (a missing one is 0); linear analyses only."""
    if table is None:
        return None
    if analysis != "linear":
        raise ProblemError(f"[body-force] is implemented for linear analyses, not {analysis!r} (gravity is "
                           "problem.gravity)", key="body-force")
    if not table:
        raise ProblemError("give bx, by or both", key="body-force")
    return BodyForce(*(values.field(table.get(k, 0.0), f"body-force.{k}") for k in ("bx", "by")))
