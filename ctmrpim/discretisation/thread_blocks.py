"""Blocks of one compiled pass, run concurrently on the calling thread and a thread pool kept for the process.

The compiled kernels (RPIM rows, stiffness and tangent rows, the gradient and force products) release the GIL, so
the blocks of rows, points or nodes of one pass run on :data:`THREADS` threads. The calling thread takes blocks
too, and the others come from one pool kept for the process: a pool started per call costs a thread start each
time (a Newton tangent is built every iteration, the explicit products every step), and waking two idle vCPUs of
this project's VM costs more than waking one (measured on the explicit step: the gradient 1.08 -> 1.22 ms per
call with both blocks on a pool, 1.37 -> 1.01 ms with the first in the calling thread). Blocks are handed out in
order from one queue, so a thread that wakes late takes fewer of them. Which thread computes a block never
changes its result: the blocks write disjoint outputs.

A forked child (a sweep's worker) makes its own pool: its copy of the parent's has no threads.
"""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable

#: threads of a pass (the calling thread and THREADS - 1 from the pool); 1: all in the calling thread
THREADS = 2

_pool: tuple[int, int, ThreadPoolExecutor] | None = None     # (process, threads, pool)
#: the numba dispatchers known to have run in this process: asking a dispatcher for its ``signatures`` costs about
#: 50 us (it hashes its types), more than one block of a small pass (an explicit step calls run_blocks once or twice)
_loaded: set[int] = set()


def executor() -> ThreadPoolExecutor:
    """The process's pool of THREADS - 1 threads (at least one), made anew in a forked child or when THREADS grew."""
    global _pool
    if _pool is None or _pool[0] != os.getpid() or _pool[1] < THREADS - 1:
        size = max(THREADS - 1, 1)
        _pool = (os.getpid(), size, ThreadPoolExecutor(max_workers=size, thread_name_prefix="blocks"))
    return _pool[2]


def run_blocks(work: Callable[[tuple[int, int]], Any], blocks: list[tuple[int, int]], kernel: Any = None) -> None:
    """``work(block)`` for every block, on THREADS threads (the calling one among them). An exception in a block
    stops the handing out of blocks, and is raised here once the blocks already started have ended. ``kernel``:
    the numba dispatcher that ``work`` calls; where it has not run in this process yet, the first block runs alone
    first, so that its cached code is loaded once (two first calls at once load it twice: 15 ms each for the RPIM
    rows, measured)."""
    blocks = list(blocks)
    if kernel is not None and id(kernel) not in _loaded:
        if blocks and not getattr(kernel, "signatures", True):
            work(blocks.pop(0))
        if getattr(kernel, "signatures", True):
            _loaded.add(id(kernel))
    if len(blocks) <= 1 or THREADS <= 1:
        for ab in blocks:
            work(ab)
        return
    queue = iter(blocks)
    lock = threading.Lock()
    failed = threading.Event()

    def drain() -> None:
        while not failed.is_set():
            with lock:
                ab = next(queue, None)
            if ab is None:
                return
            try:
                work(ab)
            except BaseException:
                failed.set()
                raise

    helpers = [executor().submit(drain) for _ in range(min(THREADS, len(blocks)) - 1)]
    try:
        drain()
    finally:
        for f in helpers:
            f.exception()       # wait for every helper before anything is raised
    for f in helpers:
        f.result()
