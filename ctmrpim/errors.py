"""The one exception type for mistakes in the user's input.

The CLI turns a :class:`ProblemError` into a one-line message and exit status 2, without a traceback;
anything else escaping is a bug in ctmrpim and keeps its traceback.
"""
from __future__ import annotations


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
        """The same error with the file or key filled in where it was not known yet."""
        return ProblemError(self.reason, source=self.source or source, key=self.key or key)
