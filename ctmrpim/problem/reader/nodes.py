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
                    file=str(table["file"]) if "file" in table else None,
                    jitter=values.number(table["jitter"], "nodes.jitter") if "jitter" in table else 0.0,
                    seed=_seed(table["seed"], values) if "seed" in table else None)


def _seed(value: Any, values: Values) -> int:
    n = values.number(value, "nodes.seed")
    if not (float(n).is_integer() and n >= 0):
        raise ProblemError(f"{value!r} must be an integer >= 0", key="nodes.seed")
    return int(n)


def _grid(value: Any, values: Values) -> tuple[int, int]:
    if not isinstance(value, list) or len(value) != 2:
        raise ProblemError(f"{value!r} must be [nx, ny]", key="nodes.grid")
    n = [values.number(v, "nodes.grid") for v in value]
    if not all(float(v).is_integer() for v in n):
        raise ProblemError(f"{value!r} must be two integers", key="nodes.grid")
    return int(n[0]), int(n[1])
