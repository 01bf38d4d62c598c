"""The size of a solve estimated from its input, before anything is allocated, and the refusal of one
that cannot fit in this machine's memory.

Without it, ``nodes.grid = [100000, 100000]`` or ``line_spacing = [1e-4, 1e-4]`` ended in numpy's
allocation error (a traceback) after a long wait, or under a memory cap in a segmentation fault.

Estimates (CTM, Section 2.2): n nodes fill the body's area A, so the node spacing is d_c = sqrt(A / n);
the integration lines lie r_x d_c apart with sub-segments r_y d_c long and ``gauss_points`` points
each, so m = A / (r_x r_y d_c^2) x gauss_points (65 x 17 cantilever: 9944 estimated, 9950 laid);
each point's support holds about pi r_c^2 nodes. The memory of a CTM-RPIM solve grows with the
point-support pairs m k: measured on the 129 x 33 cantilever (38318 points, 46 nodes per support),
546 MB peak, of which about 120 MB is the interpreter and its libraries: 240 bytes per pair.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

from ctmrpim.errors import ProblemError
from ctmrpim.problem.case import Case

#: bytes per integration point and support node of a CTM-RPIM solve (module docstring), rounded up
BYTES_PER_PAIR = 256
#: bytes per node of a finite-element solve on the same nodes (P2: about 4 times the vertices' dofs)
BYTES_PER_FEM_NODE = 20_000
#: the interpreter and its libraries
BASELINE_BYTES = 150e6


@dataclass(frozen=True)
class SizeEstimate:
    """Nodes, integration points, support size and peak memory (bytes) expected of a solve."""

    nodes: float
    points: float
    support: float
    memory: float


def estimate(case: Case, method: str = "ctm-rpim") -> SizeEstimate:
    """The size of solving ``case`` with ``method`` (module docstring), from its input alone."""
    geometry, spec, m = case.problem.geometry, case.nodes, case.method
    area = geometry.area
    if spec.grid is not None:
        x0, y0, x1, y1 = geometry.bounds
        n = spec.grid[0] * spec.grid[1] * min(1.0, area / max((x1 - x0) * (y1 - y0), 1e-300))
    elif spec.spacing is not None:
        n = area / spec.spacing ** 2
    else:
        n = _lines(Path(case.base_dir) / spec.file)
    n = max(n, 1.0)
    d_c = math.sqrt(area / n)
    r_x, r_y = m.line_spacing
    points = area / (r_x * r_y * d_c ** 2) * m.gauss_points
    support = max(math.pi * m.support_radius ** 2, 1.0)
    if method == "ctm-rpim":
        memory = BASELINE_BYTES + BYTES_PER_PAIR * points * support
    else:
        memory = BASELINE_BYTES + BYTES_PER_FEM_NODE * n
    return SizeEstimate(nodes=n, points=points if method == "ctm-rpim" else 0.0, support=support, memory=memory)


def check_fits(case: Case, method: str = "ctm-rpim") -> SizeEstimate:
    """Refuse ``case`` when its estimated memory exceeds this machine's (the smaller of the physical memory
    and a container's limit), with the estimate in the message; the estimate otherwise."""
    size = estimate(case, method)
    limit = memory_limit()
    if limit is not None and size.memory > limit:
        what = (f"{size.nodes:.3g} nodes and {size.points:.3g} integration points" if size.points
                else f"{size.nodes:.3g} nodes")
        key = "method.line_spacing" if size.points > 1e3 * size.nodes else "nodes"
        raise ProblemError(f"too large for this machine: {what} need about {_gib(size.memory)} of memory, "
                           f"and it has {_gib(limit)}", key=key)
    return size


def memory_limit() -> float | None:
    """Bytes this process may use: physical memory, or a cgroup's limit where that is lower; None if unknown."""
    limits = []
    try:
        limits.append(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        pass
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            text = Path(path).read_text().strip()
        except OSError:
            continue
        if text.isdigit():
            limits.append(int(text))
    return float(min(limits)) if limits else None


def _lines(path: Path) -> float:
    """Rows of a node file (its newlines), without parsing it; 1 if it cannot be read (the reader says why)."""
    try:
        with open(path, "rb") as f:
            return float(sum(chunk.count(b"\n") for chunk in iter(lambda: f.read(1 << 20), b"")))
    except OSError:
        return 1.0


def _gib(nbytes: float) -> str:
    return f"{nbytes / 2 ** 30:.3g} GiB"
