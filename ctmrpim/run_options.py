"""What a solve is told beyond its case: how it reports progress and where a long run writes as it goes.

Phases, Newton iterations and explicit steps go to the progress reporter in force
(:func:`ctmrpim.progress.current`, installed by ``ctmrpim run``), not through these options, so that a
solver deep in the call chain needs no reporter handed down; ``progress`` is the one callback with a result
in it (each strength-reduction level, which the command line prints as a line of its own).
"""
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
    progress_bar: bool = False       # explicit dynamics: report its steps to the progress reporter in force
