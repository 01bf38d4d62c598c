"""What a solve is told beyond its case: how it reports progress and where a long run writes as it goes."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable


@dataclass(frozen=True)
class RunOptions:
    """How a solve reports and where it writes as it goes (explicit dynamics: series and checkpoints)."""

    progress: Callable[[Any], None] = field(default=lambda level: None)   # each strength-reduction level
    out: Path | None = None          # folder for a long run's series and checkpoints (a temporary one if None)
    resume: bool = False             # continue from the checkpoint in ``out``
    progress_bar: bool = False
