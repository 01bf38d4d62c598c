"""The manufactured solution's cases (the problem itself is the benchmark ``manufactured``: a smooth
non-polynomial field with its body force on a plate with a hole and a curved end), and the exact traction of a
stress field as a ``[[traction]]`` entry (the patch tests' cases)."""
from __future__ import annotations

from ctmrpim import benchmarks
from ctmrpim.problem.case import Case


def exact_traction(where: str, nx: str | float, ny: str | float, field: dict) -> dict:
    """A ``[[traction]]`` entry: the traction sigma n of ``field`` (stresses as expressions) on the edges ``where``,
    the outward normal (nx, ny) numbers or expressions of x and y."""
    return {"where": where, "tx": f"({nx})*({field['sxx']}) + ({ny})*({field['sxy']})",
            "ty": f"({nx})*({field['sxy']}) + ({ny})*({field['syy']})"}


def manufactured_case(spacing: float, method: dict | None = None) -> Case:
    """The benchmark ``manufactured`` on a node cloud of ``spacing``, with ``method`` settings."""
    settings = [f"method.{k}={v!r}" if isinstance(v, str) else f"method.{k}={v}" for k, v in (method or {}).items()]
    return benchmarks.load("manufactured", [f"nodes.spacing={spacing}", *settings])
