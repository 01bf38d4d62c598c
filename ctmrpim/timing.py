"""Wall time per phase of a solve, the one way every solver (and the FE reference) measures it.

``summary.json`` reports ``timings`` as ``{phase: seconds, ..., "total": seconds}``. A solver either
takes laps (``timer.lap("assembly")`` books the time since the last lap) or measures a block that
recurs, such as one phase of every Newton iteration (``with timer.measure("tangent"): ...``, summed).

Each lap is also told to the progress reporter in force (:func:`ctmrpim.progress.current`: silent unless
``ctmrpim run`` installed one), so every solver shows its phases without being handed a reporter.
"""
from __future__ import annotations

import time
from contextlib import contextmanager
from typing import Iterator

from ctmrpim import progress


class Timer:
    """Phases of one solve, in seconds (``time.perf_counter``), started at construction."""

    def __init__(self) -> None:
        self.t0 = self.last = time.perf_counter()
        self.phases: dict[str, float] = {}

    def add(self, name: str, seconds: float) -> None:
        """Book ``seconds`` to phase ``name`` (phases sum over repeated bookings)."""
        self.phases[name] = self.phases.get(name, 0.0) + seconds

    def lap(self, name: str, **counts: int) -> None:
        """Book the time since the previous lap (or the start) to phase ``name``, and report it with what the
        phase counted (e.g. ``nodes=16705``) to the progress reporter."""
        now = time.perf_counter()
        self.add(name, now - self.last)
        progress.current().phase(name, now - self.last, **counts)
        self.last = now

    @contextmanager
    def measure(self, name: str) -> Iterator[None]:
        """Book the time spent inside the ``with`` block to phase ``name`` (laps are not moved)."""
        start = time.perf_counter()
        try:
            yield
        finally:
            self.add(name, time.perf_counter() - start)

    def elapsed(self) -> float:
        """Seconds since the start."""
        return time.perf_counter() - self.t0

    def total(self) -> dict[str, float]:
        """The phases and ``total``, the time since the start."""
        return {**self.phases, "total": self.elapsed()}
