"""The ``[nodes]`` table: a tensor grid, a spacing or a CSV file."""
from __future__ import annotations

from typing import Any

from ctmrpim.errors import ProblemError
from ctmrpim.problem.node_cloud import NodeSpec
from ctmrpim.problem.reader.values import Values


def read_nodes(values: Values) -> NodeSpec:
    """How the body is filled with nodes (exactly one of ``grid``, ``spacing`` and ``file``)."""
    table = values.raw.get("nodes")
    if not table:
        raise ProblemError("missing section [nodes] (grid = [nx, ny], spacing = h or file = ...)", key="nodes")
    return NodeSpec(grid=_grid(table["grid"], values) if "grid" in table else None,
                    spacing=values.number(table["spacing"], "nodes.spacing") if "spacing" in table else None,
                    file=str(table["file"]) if "file" in table else None)


def _grid(value: Any, values: Values) -> tuple[int, int]:
    if not isinstance(value, list) or len(value) != 2:
        raise ProblemError(f"{value!r} must be [nx, ny]", key="nodes.grid")
    n = [values.number(v, "nodes.grid") for v in value]
    if not all(float(v).is_integer() for v in n):
        raise ProblemError(f"{value!r} must be two integers", key="nodes.grid")
    return int(n[0]), int(n[1])
