"""Why an explicit run stops: :class:`Diverged`, raised by the frame, the step, the rebuilds and the driver."""
from __future__ import annotations

from ctmrpim.errors import ProblemError


class Diverged(ProblemError):
    """The run cannot go on; the message says what, where and when."""
