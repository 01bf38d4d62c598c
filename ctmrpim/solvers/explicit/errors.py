"""Why an explicit run stops: :class:`Diverged`, raised by the frame, the step, the rebuilds and the driver."""
from __future__ import annotations

from ctmrpim.errors import ConvergenceError


class Diverged(ConvergenceError):
    """The run cannot go on (the input was accepted; the solve did not converge: exit status 3 from the CLI); the
    message says what, where and when, and the driver adds the history recorded up to there."""
