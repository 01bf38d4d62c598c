"""The ``[geometry]`` table: shapes added and subtracted, their numbers read as expressions."""
from __future__ import annotations

from ctmrpim.errors import ProblemError
from ctmrpim.problem.geometry import Geometry, Shape
from ctmrpim.problem.reader.keys import suggest
from ctmrpim.problem.reader.values import Values

SHAPES = ("rectangle", "polygon", "circle")


def read_geometry(table: dict, values: Values) -> Geometry:
    """The body: ``add`` and ``subtract`` lists of ``{rectangle = [...]}``, ``{polygon = [...]}``, ``{circle = [...]}``."""
    try:
        return Geometry(add=_shapes(table, "add", values), subtract=_shapes(table, "subtract", values))
    except ProblemError as exc:
        raise exc.at(key="geometry") from None


def _shapes(table: dict, key: str, values: Values) -> list[Shape]:
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
            out.append(_shape(kind, data, where, values))
            out[-1].polygon()  # validates
        except ProblemError as exc:
            raise exc.at(key=where) from None
    return out


def _shape(kind: str, data: object, where: str, values: Values) -> Shape:
    if kind in ("rectangle", "circle"):
        n = 4 if kind == "rectangle" else 3
        if not isinstance(data, list) or len(data) != n:
            raise ProblemError(f"{kind} needs {n} numbers")
        return Shape(kind, tuple(values.number(v, where) for v in data))
    if kind == "polygon":
        if not isinstance(data, list) or not all(isinstance(p, list) and len(p) == 2 for p in data):
            raise ProblemError("polygon needs a list of [x, y] vertices")
        return Shape(kind, tuple((values.number(p[0], where), values.number(p[1], where)) for p in data))
    raise ProblemError(f"unknown shape {kind!r}{suggest(kind, list(SHAPES))}")
