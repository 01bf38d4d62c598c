"""Cases by name or file: :func:`load_case` reads a benchmark (``"cantilever"``) or a problem file."""
from __future__ import annotations

import difflib
from pathlib import Path
from typing import Iterable

import ctmrpim.benchmarks as benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.problem.case import Case
from ctmrpim.problem.reader import read_case


def load_case(target: str | Path, overrides: Iterable[str] = ()) -> Case:
    """The :class:`Case` of a benchmark name (see ``ctmrpim list``) or of a TOML problem file, with
    ``overrides`` (``"section.key=value"``, TOML values) applied; bad input is a ProblemError."""
    overrides = list(overrides)
    target = str(target)
    if target in benchmarks.names():
        return benchmarks.load(target, overrides)
    p = Path(target)
    if p.suffix == ".toml" or p.exists():
        return read_case(p, overrides)
    close = difflib.get_close_matches(target, benchmarks.names(), n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    raise ProblemError(f"{target!r} is neither a benchmark ({', '.join(benchmarks.names())}) nor a problem file{hint}")
