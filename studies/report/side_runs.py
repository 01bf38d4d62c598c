"""The report's work besides the sweep's cases, spread over the cores the sweep was given.

Four runs need fields that the sweep does not cache (its cases keep summaries): the models' figures (Figs. 6 and
8), the deformed shapes (Figs. 15 and 17), the stability fields (Figs. 20 and 25) and the momentum conservation of
the explicit solver. They depend on no table, so :class:`SideRuns` starts them in a process of their own before
the sweep and they run while its workers compute the cases (filling the cores the sweep's last, long cases leave
idle). Once the cases are done, :func:`study_tables` reads, tabulates and draws the studies in a pool of the same
size. Each run's progress lines come back with its result and are replayed, in order, by the client.

With one worker (``--workers 1``: everything in this process) or a Dask scheduler (the cores are elsewhere), the
runs happen here, one after another, as before.
"""
from __future__ import annotations

from concurrent.futures import Future, ProcessPoolExecutor
from multiprocessing import get_all_start_methods, get_context
from pathlib import Path
from typing import Any, Callable

import pandas as pd

import studies
from studies import deformed_shapes, explicit_conservation, model_figures, stability_fields
from studies.report.markdown import Progress
from studies.sweep import Sweep, one_core_worker, warm_up_for_fork

#: the runs that need fields, by name: ``(quick, out_dir, progress) -> result``, longest first
RUNS: dict[str, Callable[[bool, Path, Progress], Any]] = {
    "deformed_shapes": deformed_shapes.run,
    "stability_fields": stability_fields.run,
    "explicit_conservation": lambda quick, out_dir, progress: _conservation(quick, progress),
    "models": model_figures.run,
}


#: the files (``NAME.csv`` / ``NAME.png``) each run writes, and the ``studies`` module that makes them: a full
#: report stamps them like the studies' results (:func:`studies.provenance.stamp`)
OUTPUTS: dict[str, tuple[str, tuple[str, ...]]] = {
    "deformed_shapes": ("deformed_shapes", ("deformed_shapes",)),
    "stability_fields": ("stability_fields", ("stability_fields",)),
    "explicit_conservation": ("explicit_conservation", ("explicit_conservation", "explicit_conservation_operators")),
    "models": ("model_figures", ("alpha_shapes", "models")),
}


def stamp_outputs(name: str, out_dir: Path) -> None:
    """Stamp the files of run ``name`` in ``out_dir`` with the code that made them (a full report's)."""
    from studies.provenance import stamp

    module, files = OUTPUTS[name]
    for stem in files:
        stamp(out_dir, stem, module=module)


def _conservation(quick: bool, progress: Progress) -> tuple[pd.DataFrame, pd.DataFrame]:
    progress("explicit_conservation: momentum of a free flight and a spin, ctm and ctm-vci")
    return explicit_conservation.measure(quick)


def _run(name: str, quick: bool, out_dir: Path) -> tuple[Any, list[str]]:
    """Run :data:`RUNS` ``name``; its result and its progress lines."""
    lines: list[str] = []
    return RUNS[name](quick, out_dir, lines.append), lines


def _table(name: str, quick: bool, out_dir: Path, sweep: Sweep) -> tuple[pd.DataFrame, list[str]]:
    """Study ``name``'s table from the sweep's cases (CSV and figure written); the table and the progress lines."""
    lines: list[str] = []
    return studies.run(name, quick, out_dir, sweep, lines.append), lines


def _one_core() -> None:
    """A side process computes on one core: one RPIM thread and one BLAS thread for its whole life."""
    from threadpoolctl import threadpool_limits

    one_core_worker()
    threadpool_limits(1)


def _pool(workers: int) -> ProcessPoolExecutor | None:
    """A pool of ``workers`` forked processes computing on one core each, or None where there is no fork (spawned
    workers would import and compile everything again: not worth it for these runs)."""
    if "fork" not in get_all_start_methods():
        return None
    warm_up_for_fork()
    return ProcessPoolExecutor(workers, mp_context=get_context("fork"), initializer=_one_core)


class SideRuns:
    """:data:`RUNS`, started on entry in a process of their own when ``parallel`` (else run here on demand)."""

    def __init__(self, quick: bool, out_dir: Path, parallel: bool) -> None:
        self.quick, self.out_dir, self.parallel = quick, Path(out_dir), parallel
        self.pool: ProcessPoolExecutor | None = None
        self.futures: dict[str, Future] = {}

    def __enter__(self) -> SideRuns:
        self.pool = _pool(1) if self.parallel else None
        if self.pool is not None:
            self.futures = {name: self.pool.submit(_run, name, self.quick, self.out_dir) for name in RUNS}
        return self

    def result(self, name: str, progress: Progress) -> Any:
        """The result of run ``name``, its progress lines replayed through ``progress`` (it runs now when it was
        not started in a process of its own)."""
        result, lines = self.futures[name].result() if name in self.futures else _run(name, self.quick, self.out_dir)
        for line in lines:
            progress(line)
        return result

    def __exit__(self, *exc: object) -> None:
        if self.pool is not None:
            self.pool.shutdown(cancel_futures=True)


def study_tables(quick: bool, out_dir: Path, sweep: Sweep, progress: Progress) -> dict[str, pd.DataFrame]:
    """Every study's table from the sweep's cases (all computed already), in a pool of the sweep's local workers
    where it has more than one; the progress lines replayed in the studies' order."""
    pool = _pool(sweep.workers) if sweep.workers > 1 and not sweep.scheduler else None
    if pool is None:
        return {name: studies.run(name, quick, out_dir, sweep, progress) for name in studies.NAMES}
    with pool:
        futures = {name: pool.submit(_table, name, quick, out_dir, sweep) for name in studies.NAMES}
        tables = {}
        for name, fut in futures.items():
            tables[name], lines = fut.result()
            for line in lines:
                progress(line)
    return tables
