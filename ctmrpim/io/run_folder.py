"""A run's output folder: ``result.vtu``, the series (``result.pvd`` + ``series/*.vtu``) and ``summary.json``,
written all or none."""
from __future__ import annotations

import shutil
from pathlib import Path

from ctmrpim.errors import ProblemError
from ctmrpim.io.summary import write_summary
from ctmrpim.io.vtu import write_series, write_vtu
from ctmrpim.problem.case import Case
from ctmrpim.result import Result


def write_outputs(result: Result, case: Case, out: Path) -> list[Path]:
    """result.vtu, the increment series (result.pvd + series/*.vtu) where there is one, and
    summary.json last; all or none (a folder this call created is removed again if a write fails, so
    a failed run never leaves a half-written result behind)."""
    created = not out.exists()
    paths: list[Path] = []
    try:
        paths.append(write_vtu(result, out))
        for p in write_series(result, out):
            paths.append(p)
        paths.append(write_summary(result, out, case.source))
    except BaseException as exc:
        for p in paths:
            p.unlink(missing_ok=True)
        if created:
            shutil.rmtree(out, ignore_errors=True)
        if isinstance(exc, OSError):  # e.g. --out names an existing file, or a read-only folder
            raise ProblemError(f"cannot write the results to {str(out)!r} ({exc.strerror or exc})",
                               key="--out") from None
        raise
    return paths
