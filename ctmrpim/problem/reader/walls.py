"""``[[wall]]``: the rigid walls (and gates) of explicit dynamics."""
from __future__ import annotations

from ctmrpim.errors import ProblemError
from ctmrpim.problem.model import NO_SLIP, Wall
from ctmrpim.problem.reader.values import Values


def check_walls_allowed(raw: dict, analysis: str) -> None:
    """Raise if the file has walls but an analysis without contact."""
    if raw.get("wall") and analysis != "explicit":
        raise ProblemError("[[wall]] (rigid contact) needs analysis = \"explicit\"", key="wall")


def read_walls(values: Values) -> list[Wall]:
    """The ``[[wall]]`` tables in file order."""
    return [_wall(c, f"wall[{i}]", values) for i, c in enumerate(values.raw.get("wall", []))]


def _wall(c: dict, where: str, values: Values) -> Wall:
    friction = c.get("friction", NO_SLIP)
    if friction != NO_SLIP:
        friction = values.number(friction, f"{where}.friction")
    gate = c.get("gate", False)
    if not isinstance(gate, bool):
        raise ProblemError(f"{gate!r} must be true or false", key=f"{where}.gate")
    vectors = []
    for k in ("point", "normal"):
        if not isinstance(c[k], list) or len(c[k]) != 2:
            raise ProblemError(f"{c[k]!r} must be [x, y]", key=f"{where}.{k}")
        vectors.append(tuple(values.number(v, f"{where}.{k}") for v in c[k]))
    try:
        return Wall(str(c["name"]), *vectors, friction=friction, gate=gate)
    except ProblemError as exc:
        # the wall names its keys by the wall's name; the file's reader knows its place in the list
        raise ProblemError(exc.reason, key=where) from None
