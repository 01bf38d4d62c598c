"""A :class:`Case`: one runnable configuration, the continuous problem plus how to discretise and solve it."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ctmrpim.problem.model import Problem
from ctmrpim.problem.node_cloud import NodeSpec
from ctmrpim.problem.settings import Explicit, Loading, Method, Relaxation, StrengthReduction


@dataclass
class Case:
    """One runnable configuration: the continuous problem plus its discretisation and method."""

    problem: Problem
    nodes: NodeSpec
    method: Method
    source: str
    base_dir: Path
    resolved: dict[str, Any] = field(default_factory=dict)
    defaults: list[str] = field(default_factory=list)
    loading: Loading = field(default_factory=Loading)
    strength_reduction: StrengthReduction | None = None
    relaxation: Relaxation | None = None          # [dynamic]: dynamic relaxation settings
    explicit: Explicit | None = None              # [explicit]: explicit dynamics settings
