"""The exception types for runs that cannot give a result.

- :class:`ProblemError`: a mistake in the user's input. The CLI turns it into a one-line message and exit
  status 2, without a traceback, and writes nothing.
- :class:`ConvergenceError` (a kind of ProblemError): the input was accepted, but the solve did not converge
  (Newton gave up after its cut-backs, an explicit run diverged). The CLI prints one line, keeps what the
  run got through (its history, an explicit run's checkpoint and series), marks the run "not converged"
  and exits with status 3. A limit-load or strength-reduction search that ends in failure is not one: that
  failure is its answer, returned as a result.

Anything else escaping is a bug in ctmrpim and keeps its traceback.
"""
from __future__ import annotations

import copy
from typing import Any


class ProblemError(Exception):
    """Bad input: names where (file, key) and why, in one line."""

    def __init__(self, reason: str, *, source: str | None = None, key: str | None = None) -> None:
        self.reason = reason
        self.source = source
        self.key = key
        super().__init__(self.message)

    @property
    def message(self) -> str:
        """The one-line message: ``source: key: reason``, leaving out what is not known."""
        parts = [p for p in (self.source, self.key) if p]
        return ": ".join(parts + [self.reason])

    def at(self, *, source: str | None = None, key: str | None = None) -> "ProblemError":
        """The same error (same type, same attributes) with the file or key filled in where it was not known
        yet."""
        new = copy.copy(self)
        new.source, new.key = self.source or source, self.key or key
        new.args = (new.message,)
        return new


class ConvergenceError(ProblemError):
    """The solve did not converge; ``history`` holds the records of what converged before (load increments,
    time records), which the CLI writes to ``summary.json`` beside the reason.

    A subclass of :class:`ProblemError` so that code written before it existed (a sweep that records any
    ProblemError as a failed case) keeps treating it as a case that cannot be solved as posed."""

    def __init__(self, reason: str, *, source: str | None = None, key: str | None = None,
                 history: list[dict[str, Any]] | None = None) -> None:
        super().__init__(reason, source=source, key=key)
        self.history: list[dict[str, Any]] = list(history or [])
