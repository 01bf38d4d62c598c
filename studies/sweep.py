"""Sweep executor: many independent cases, run locally in processes or on a Dask cluster, cached.

Every case gets a folder under the sweep's root named by a hash of its *resolved* input (the full
problem after defaults and overrides, the solver and element, and the version of the code that
computes it, so that changed code never serves a stale cached result), holding
``summary.json`` and ``status.json`` (start, end, status, error). A case counts as done when its
status is ``ok`` with the same hash: a re-run skips it, so an interrupted sweep resumes where it
stopped; a failed case keeps its error and is retried only when asked (``retry_failed``).

Local runs use a process pool (``workers``, one BLAS thread and one RPIM thread per worker so that
P workers do not fight over the cores); ``scheduler="tcp://..."`` sends the same work to a
``dask.distributed`` cluster instead. Post-processing reads the case folders and can be redone alone.
"""
from __future__ import annotations

import hashlib
import json
import sys
import time
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field
from functools import cache
from multiprocessing import get_all_start_methods, get_context
from pathlib import Path
from typing import Any, Iterable

from ctmrpim.cases import load_case
from ctmrpim.errors import ProblemError
from ctmrpim.io.atomic import atomic_write_text
from ctmrpim.io.provenance import code_version, source_hash
from ctmrpim.io.summary import to_jsonable, write_summary
from ctmrpim.methods import solve


@dataclass(frozen=True)
class CaseSpec:
    """One case of a sweep: a benchmark name or problem file, overrides, and the method."""

    target: str
    overrides: tuple[str, ...] = ()
    solver: str = "ctm-rpim"
    element: str | None = None          # the method's element (None: its default, or none)
    labels: tuple[tuple[str, Any], ...] = field(default=(), compare=False)  # study coordinates, not hashed

    def label_dict(self) -> dict[str, Any]:
        """The study coordinates as a dict (label -> value)."""
        return dict(self.labels)


def element_for(solver: str, element: str) -> str | None:
    """``element`` for a method that has elements (a finite-element reference), None for one that has none
    (CTM-RPIM), so that one study can list both methods with one element."""
    from ctmrpim.methods import get

    return element if get(solver).elements else None


@cache
def method_version(name: str) -> str:
    """The version of the code behind the method ``name``: this package's (:func:`code_version`), plus
    the source hash of the package that registered the method where that is another one (the
    finite-element reference)."""
    from ctmrpim.methods import get

    package = get(name).solve.__module__.split(".")[0]
    if package == "ctmrpim":
        return code_version()
    return f"{code_version()}+{package}-{source_hash(Path(sys.modules[package].__file__).parent)[:16]}"


def case_hash(spec: CaseSpec) -> str:
    """sha256 of the resolved input, the method and element, and the version of the code that computes
    them (this package's and the method's: never the sweep's, the studies' or the report's)."""
    case = load_case(spec.target, list(spec.overrides))
    payload = {"resolved": case.resolved, "solver": spec.solver, "element": spec.element,
               "version": method_version(spec.solver)}
    text = json.dumps(to_jsonable(payload), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


_warm = False


def _warm_up() -> None:
    """Solve a tiny case with each method once per process, so that lazy imports and first-call
    set-up costs stay out of the wall times the studies compare."""
    global _warm
    if _warm:
        return
    tiny = load_case("cantilever", ["nodes.grid=[9, 3]"])
    for solver, element in (("ctm-rpim", None), ("fem", "q1"), ("fem", "p2")):
        solve(tiny, solver, element)
    _warm = True


def _worker_setup() -> None:
    """A worker process computes on one core: one RPIM thread (BLAS is limited per case)."""
    from ctmrpim.discretisation import rpim

    rpim.THREADS = 1


def run_case(spec: CaseSpec, folder: str, key: str, worker: bool = True) -> dict[str, Any]:
    """Solve one case and write its folder; returns the status record (never raises for a bad case).

    BLAS runs on one thread in every mode, so that a case gives the same bits in-process, in a local
    worker and on a Dask worker (the RPIM thread count does not change any result).
    """
    from threadpoolctl import threadpool_limits

    if worker:
        _worker_setup()
    with threadpool_limits(1):
        _warm_up()
    folder_path = Path(folder)
    status: dict[str, Any] = {"hash": key, "spec": asdict(spec), "start": time.time()}
    try:
        case = load_case(spec.target, list(spec.overrides))
        with threadpool_limits(1):
            result = solve(case, spec.solver, spec.element, out=folder_path,   # explicit runs: series, checkpoints
                           resume=(folder_path / "checkpoint.npz").is_file())
        write_summary(result, folder_path, case.source)
        status.update(status="ok")
    except ProblemError as exc:
        status.update(status="error", error=exc.message)
    except Exception as exc:  # a bug, recorded with its traceback so the sweep goes on
        status.update(status="error", error=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc())
    status["end"] = time.time()
    atomic_write_text(folder_path / "status.json", json.dumps(to_jsonable(status), indent=1) + "\n")
    return status


@dataclass
class CaseOutcome:
    """One case of a sweep after it ran (or was found in the cache): its folder, status (``ok`` or ``error``),
    its ``summary.json`` as a dict (None unless ok) and the error message."""
    spec: CaseSpec
    folder: Path
    status: str
    summary: dict[str, Any] | None
    error: str | None = None
    cached: bool = False


class Sweep:
    """Run CaseSpecs into ``root`` with caching; see the module docstring."""

    def __init__(self, root: Path | str, workers: int = 1, scheduler: str | None = None,
                 progress: bool = True, retry_failed: bool = False) -> None:
        self.root = Path(root)
        self.workers = max(1, int(workers))
        self.scheduler = scheduler
        self.progress = progress
        self.retry_failed = retry_failed
        self.computed = 0   # cases actually run by the last call of run()

    def folder(self, key: str) -> Path:
        """The case folder of hash ``key``: the root's subfolder named by its first 16 hex digits."""
        return self.root / key[:16]

    def _done(self, key: str) -> dict[str, Any] | None:
        f = self.folder(key) / "status.json"
        if not f.is_file():
            return None
        status = json.loads(f.read_text())
        if status.get("hash") != key:
            return None
        if status.get("status") == "ok" and (self.folder(key) / "summary.json").is_file():
            return status
        if status.get("status") == "error" and not self.retry_failed:
            return status
        return None

    def run(self, specs: Iterable[CaseSpec], desc: str = "sweep") -> list[CaseOutcome]:
        """Run the cases of ``specs`` not done yet (each distinct hash once; ``desc`` labels the progress bar) and
        return the outcomes of all of them, in the order of ``specs``."""
        specs = list(specs)
        keys = [case_hash(s) for s in specs]
        todo = [i for i, k in enumerate(keys) if self._done(k) is None]
        unique: dict[str, int] = {}
        for i in todo:
            unique.setdefault(keys[i], i)
        self.computed = len(unique)
        if unique:
            self._execute([(specs[i], str(self.folder(k)), k) for k, i in unique.items()], desc)
        out = []
        for spec, key in zip(specs, keys):
            status = self._done(key) or {"status": "error", "error": "no status record was written"}
            folder = self.folder(key)
            summary = json.loads((folder / "summary.json").read_text()) if status["status"] == "ok" else None
            out.append(CaseOutcome(spec=spec, folder=folder, status=status["status"], summary=summary,
                                   error=status.get("error"), cached=key not in unique))
        return out

    def _execute(self, jobs: list[tuple[CaseSpec, str, str]], desc: str) -> None:
        from tqdm import tqdm

        for _, folder, _ in jobs:
            Path(folder).mkdir(parents=True, exist_ok=True)
        bar = tqdm(total=len(jobs), desc=desc, unit="case", disable=not self.progress, leave=False)
        try:
            if self.scheduler:
                self._execute_dask(jobs, bar)
            elif self.workers == 1:
                for job in jobs:
                    run_case(*job, worker=False)
                    bar.update()
            else:
                # fork needs no `if __name__ == "__main__"` guard in the caller's script; the parent holds
                # no threads of ours between cases (RPIM's pool lives only inside one call)
                ctx = get_context("fork" if "fork" in get_all_start_methods() else "spawn")
                with ProcessPoolExecutor(self.workers, mp_context=ctx, initializer=_worker_setup) as pool:
                    for fut in as_completed([pool.submit(run_case, *job) for job in jobs]):
                        fut.result()
                        bar.update()
        finally:
            bar.close()

    def _execute_dask(self, jobs: list[tuple[CaseSpec, str, str]], bar) -> None:
        try:
            from dask.distributed import Client
            from dask.distributed import as_completed as dask_completed
        except ImportError:
            raise ProblemError("--scheduler needs dask.distributed: pip install 'ctmrpim[dask]'") from None
        try:
            client = Client(self.scheduler, timeout="10s")
        except OSError as exc:
            raise ProblemError(f"cannot reach the Dask scheduler at {self.scheduler!r} ({exc})") from None
        try:
            futures = [client.submit(run_case, *job, pure=False) for job in jobs]
            for fut in dask_completed(futures):
                fut.result()
                bar.update()
        finally:
            client.close()
