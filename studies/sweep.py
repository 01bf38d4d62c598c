"""Sweep executor: many independent cases, run locally in processes or on a Dask cluster, cached.

Every case gets a folder under the sweep's root named by a hash of its *resolved* input (the full
problem after defaults and overrides, the solver and element, and the version of the code that
computes it, so that changed code never serves a stale cached result), holding
``summary.json`` and ``status.json`` (start, end, status, error) and, for explicit runs, the time
series. A case counts as done when its status is ``ok`` with the same hash: a re-run skips it, so an
interrupted sweep resumes where it stopped. A case that failed (status ``error``: bad settings, a
diverged solve) keeps its error and is retried only when asked (``retry_failed``); one that could
not run where it was sent (status ``failed``: a worker of another code version, a worker that died)
is retried on every run, and the sweep ends with a :class:`ProblemError` naming the cause, since its
table would have holes for a reason that is not the case's.

Local runs use a process pool (``workers``, one BLAS thread and one RPIM thread per worker so that
P workers do not fight over the cores) whose workers write each case folder in place.
``scheduler="tcp://..."`` sends the same work to a ``dask.distributed`` cluster instead (start the
workers with ``--nthreads 1``). Workers there run in folders of their own, often on other machines,
so a Dask worker solves in a scratch folder and returns the status record and every file the case
wrote; the client writes them into the case folder. The client loads each case itself and sends the
resolved :class:`Case`, so the worker computes exactly what was hashed, and sends the code version it
hashed; a worker whose own version differs refuses the case (status ``failed``, both versions named).
Cases that read files at solve time (a node file) need them at the same path on the workers.
Post-processing reads the case folders and can be redone alone.
"""
from __future__ import annotations

import hashlib
import json
import shutil
import socket
import sys
import tempfile
import time
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field
from functools import cache
from multiprocessing import get_all_start_methods, get_context
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Iterable

from ctmrpim.cases import load_case
from ctmrpim.errors import ProblemError
from ctmrpim.io.atomic import atomic_write, atomic_write_text
from ctmrpim.io.provenance import code_version, source_hash
from ctmrpim.io.summary import to_jsonable, write_summary
from ctmrpim.methods import solve

if TYPE_CHECKING:
    from ctmrpim.problem.case import Case


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
    return resolve_case(spec)[1]


def resolve_case(spec: CaseSpec) -> tuple[Case, str]:
    """The :class:`Case` of ``spec`` and its hash (:func:`case_hash`), loaded once for both: the client sends
    this Case to the worker, so the worker computes what was hashed even where its benchmark files differ."""
    case = load_case(spec.target, list(spec.overrides))
    payload = {"resolved": case.resolved, "solver": spec.solver, "element": spec.element,
               "version": method_version(spec.solver)}
    text = json.dumps(to_jsonable(payload), sort_keys=True)
    return case, hashlib.sha256(text.encode()).hexdigest()


_warm = False


#: cases solved once per process before any timed one: the tiny one takes every method's small-size path (lazy
#: imports, first-call set-up); the 65 x 17 cantilever is above the compiled thresholds of the shape functions,
#: the assembly and the solve (``rpim.COMPILED_MIN_POINTS``, ``assembly.COMPILED_MIN_ENTRIES``), with the
#: default (non-symmetric) and the paper's (symmetric) integration and the banded solver that larger clouds
#: take, so that numba compiles or loads those kernels here and not inside the first large case: measured from
#: an empty kernel cache, that case's wall time held 19-25 s of compilation (a 65 x 17 cantilever in 1.4 s
#: counted as 31 s), which the time-to-accuracy and node density studies then reported as solver time.
WARM_UP = ((("nodes.grid=[9, 3]",), (("ctm-rpim", None), ("fem", "q1"), ("fem", "p2"))),
           (("nodes.grid=[65, 17]", 'method.solver="banded"'), (("ctm-rpim", None),)),
           (("nodes.grid=[65, 17]", 'method.integration="ctm"', 'method.solver="banded"'), (("ctm-rpim", None),)))


def _warm_up() -> None:
    """Solve the :data:`WARM_UP` cases once per process, so that lazy imports, first-call set-up and kernel
    compilation stay out of the wall times the studies compare. The client calls it before it forks its local
    workers, which then inherit the compiled kernels (compiled once, not once per worker)."""
    global _warm
    if _warm:
        return
    for overrides, methods in WARM_UP:
        case = load_case("cantilever", list(overrides))
        for solver, element in methods:
            solve(case, solver, element)
    _warm = True


def warm_up() -> None:
    """:func:`_warm_up` on one BLAS thread: in each process that times cases, and in the client before it forks
    workers, which then inherit what it compiled."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1):
        _warm_up()


def one_core_worker() -> None:
    """A worker process computes on one core: one thread for the compiled passes (RPIM, assembly, the gradient
    products; BLAS is limited per case)."""
    from ctmrpim.discretisation import thread_blocks

    thread_blocks.THREADS = 1


@dataclass
class CaseRun:
    """What running one case hands back to the client: its status record (``hash``, ``spec``, ``start``,
    ``end``, ``status``, ``error``) and, when it ran in a scratch folder (a Dask worker), the files it wrote
    there (path relative to the case folder -> contents); empty when it wrote the case folder in place."""
    status: dict[str, Any]
    files: dict[str, bytes] = field(default_factory=dict)


def run_case(spec: CaseSpec, case: Case, key: str, version: str, folder: str | None = None,
             worker: bool = True) -> CaseRun:
    """Solve ``case`` (the resolved input of ``spec``, hash ``key``) computed by code of ``version``; never
    raises for a bad case.

    In ``folder`` when given (a local run: the files are written in place, and an explicit run resumes
    from a checkpoint there); otherwise in a scratch folder whose files come back in the :class:`CaseRun`,
    since a remote worker's file system is not the client's. The status record is the caller's to write.
    A worker whose code version is not ``version`` refuses the case (status ``failed``): its result would
    be cached under a hash that does not describe it. BLAS runs on one thread in every mode, so that a case
    gives the same bits in-process, in a local worker and on a Dask worker (the RPIM thread count does not
    change any result).
    """
    status: dict[str, Any] = {"hash": key, "spec": asdict(spec), "start": time.time()}
    mine = method_version(spec.solver)
    if mine != version:
        status.update(status="failed", end=time.time(),
                      error=f"worker {socket.gethostname()} has code version {mine} but the client {version}: "
                            "install the client's code on the workers")
        return CaseRun(status)
    if folder is not None:
        return CaseRun(_solve_into(spec, case, Path(folder), status, worker))
    scratch = Path(tempfile.mkdtemp(prefix=f"ctmrpim-case-{key[:16]}-"))
    try:
        status = _solve_into(spec, case, scratch, status, worker)
        files = {p.relative_to(scratch).as_posix(): p.read_bytes() for p in sorted(scratch.rglob("*")) if p.is_file()}
        return CaseRun(status, files)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def _solve_into(spec: CaseSpec, case: Case, folder: Path, status: dict[str, Any], worker: bool) -> dict[str, Any]:
    """Solve ``case`` with ``spec``'s method into ``folder`` (``summary.json``, an explicit run's series and
    checkpoints); ``status`` completed with the outcome."""
    from threadpoolctl import threadpool_limits

    if worker:
        one_core_worker()
    warm_up()
    try:
        with threadpool_limits(1):
            result = solve(case, spec.solver, spec.element, out=folder,   # explicit runs: series, checkpoints
                           resume=(folder / "checkpoint.npz").is_file())
        write_summary(result, folder, case.source)
        status.update(status="ok")
    except ProblemError as exc:
        status.update(status="error", error=exc.message)
    except Exception as exc:  # a bug, recorded with its traceback so the sweep goes on
        status.update(status="error", error=f"{type(exc).__name__}: {exc}", traceback=traceback.format_exc())
    status["end"] = time.time()
    return status


@dataclass
class CaseOutcome:
    """One case of a sweep after it ran (or was found in the cache): its folder, status (``ok``, ``error``
    or ``failed``, see the module docstring), its ``summary.json`` as a dict (None unless ok) and the error
    message."""
    spec: CaseSpec
    folder: Path
    status: str
    summary: dict[str, Any] | None
    error: str | None = None
    cached: bool = False


#: a job for a worker: the spec, its resolved case and its hash
Job = tuple[CaseSpec, "Case", str]

#: relative work of a solve per integration point and support node, by analysis: a linear solve builds and solves
#: once; a load path, a strength-reduction search and an explicit run repeat their residuals hundreds to thousands
#: of times. Only the order in which a sweep hands out its cases depends on it (longest first, so that no core
#: idles behind one long case at the end), never a result.
ANALYSIS_WORK = {"linear": 1.0, "quasi-static": 100.0, "strength-reduction": 300.0, "explicit": 1000.0}
#: the same for a finite-element reference on the same nodes (fewer points, smaller supports)
REFERENCE_WORK = 0.25


def expected_cost(job: Job) -> float:
    """A rough measure of how long ``job`` will take (:data:`ANALYSIS_WORK` x integration points x support nodes,
    from the input alone; :data:`REFERENCE_WORK` of it for another method), for the order of a sweep's cases."""
    from ctmrpim.problem.size_estimate import estimate

    spec, case = job[0], job[1]
    size = estimate(case)
    method = 1.0 if spec.solver == "ctm-rpim" else REFERENCE_WORK
    return method * ANALYSIS_WORK.get(case.problem.analysis, 1.0) * size.points * size.support


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
        return the outcomes of all of them, in the order of ``specs``; a ProblemError once every case ran if some
        could not run where they were sent (status ``failed``)."""
        specs = list(specs)
        resolved = [resolve_case(s) for s in specs]
        keys = [k for _, k in resolved]
        statuses = {k: self._done(k) for k in dict.fromkeys(keys)}
        jobs = {k: (specs[i], resolved[i][0], k) for i, k in enumerate(keys) if statuses[k] is None}
        self.computed = len(jobs)
        if jobs:
            statuses.update(self._execute(sorted(jobs.values(), key=expected_cost, reverse=True), desc))
        out = []
        for spec, key in zip(specs, keys):
            status = statuses[key]
            folder = self.folder(key)
            summary = json.loads((folder / "summary.json").read_text()) if status["status"] == "ok" else None
            out.append(CaseOutcome(spec=spec, folder=folder, status=status["status"], summary=summary,
                                   error=status.get("error"), cached=key not in jobs))
        failed = [o for o in out if o.status == "failed"]
        if failed:
            raise ProblemError(f"{len(failed)} of {len(out)} cases could not run ({failed[0].error}); "
                               "run again once that is fixed (finished cases are cached)")
        return out

    def store(self, key: str, run: CaseRun) -> dict[str, Any]:
        """Write what ``run`` brought back into the case folder of ``key``, the status record last (so that the
        case counts as done only once its files are all there); the status record."""
        folder = self.folder(key)
        for name, data in run.files.items():
            atomic_write(folder / name, lambda p, data=data: p.write_bytes(data))
        atomic_write_text(folder / "status.json", json.dumps(to_jsonable(run.status), indent=1) + "\n")
        return run.status

    def _execute(self, jobs: list[Job], desc: str) -> dict[str, dict[str, Any]]:
        """Run ``jobs`` and store each as it finishes; hash -> status record."""
        from tqdm import tqdm

        statuses: dict[str, dict[str, Any]] = {}
        bar = tqdm(total=len(jobs), desc=desc, unit="case", disable=not self.progress, leave=False)

        def finish(job: Job, run: Callable[[], CaseRun]) -> None:
            try:
                outcome = run()
            except Exception as exc:  # the worker itself failed (died, could not load our code): not the case's fault
                outcome = CaseRun({"hash": job[2], "spec": asdict(job[0]), "status": "failed",
                                   "error": f"the worker failed: {type(exc).__name__}: {exc}"})
            statuses[job[2]] = self.store(job[2], outcome)
            bar.update()

        try:
            if self.scheduler:
                self._execute_dask(jobs, finish)
                return statuses
            for job in jobs:
                self.folder(job[2]).mkdir(parents=True, exist_ok=True)
            if self.workers == 1:
                for job in jobs:
                    finish(job, lambda job=job: run_case(*job, method_version(job[0].solver),
                                                        str(self.folder(job[2])), worker=False))
            else:
                # fork needs no `if __name__ == "__main__"` guard in the caller's script; the parent holds
                # no threads of ours between cases (RPIM's pool lives only inside one call)
                ctx = get_context("fork" if "fork" in get_all_start_methods() else "spawn")
                if ctx.get_start_method() == "fork":   # the workers inherit what the warm-up compiled
                    warm_up()
                with ProcessPoolExecutor(self.workers, mp_context=ctx, initializer=one_core_worker) as pool:
                    futures = {pool.submit(run_case, *job, method_version(job[0].solver), str(self.folder(job[2]))): job
                               for job in jobs}
                    for fut in as_completed(futures):
                        finish(futures[fut], fut.result)
        finally:
            bar.close()
        return statuses

    def _execute_dask(self, jobs: list[Job], finish: Callable[[Job, Callable[[], CaseRun]], None]) -> None:
        """Run ``jobs`` on the Dask scheduler; each result, files included, comes back to ``finish``."""
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
            futures = {client.submit(run_case, *job, method_version(job[0].solver), pure=False): job for job in jobs}
            for fut in dask_completed(futures):
                finish(futures[fut], fut.result)
                fut.release()    # the worker may drop the files now that the client holds them
        finally:
            client.close()
