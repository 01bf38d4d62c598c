"""One BLAS thread around a block of work, without reading the process's loaded libraries again each time.

``threadpoolctl.threadpool_limits`` finds the BLAS libraries by scanning the process's memory maps on every
call: 2-3 ms, paid on every linear solve of a Newton iteration (116 calls took 0.4 s of a 5.8 s tip-load run,
7 %). A :class:`threadpoolctl.ThreadpoolController` made once holds what it found; its ``limit`` sets and
restores the thread counts alone. It is made at the first call; scipy.linalg is imported here first, so that
scipy's BLAS is loaded beside numpy's before the controller looks.
"""
from __future__ import annotations

from functools import cache
from typing import Any

import scipy.linalg  # noqa: F401  (scipy's BLAS loaded before the controller looks)
from threadpoolctl import ThreadpoolController


@cache
def _controller() -> ThreadpoolController:
    return ThreadpoolController()


def one_blas_thread() -> Any:
    """A context manager that runs its block on one BLAS thread (the thread counts restored on exit)."""
    return _controller().limit(limits=1, user_api="blas")
