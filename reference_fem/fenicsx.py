"""FEniCSx (dolfinx) as the method ``"fenicsx"`` of :mod:`ctmrpim.methods` (``METHOD``, the entry point
``ctmrpim.methods: fenicsx``): an independent third reference that shares no code with CTM-RPIM or scikit-fem.

dolfinx is not on PyPI for the project's interpreter; Debian's ``python3-dolfinx`` (dolfinx 0.5) installs it
for the system interpreter. So the bridge runs that interpreter in isolated mode (``/usr/bin/python3 -I``, or
``$CTMRPIM_FENICSX_PYTHON``) with a clean environment, on the worker shipped beside this module
(:mod:`reference_fem.fenicsx_worker`), in a temporary folder: the case goes in as plain data
(:mod:`reference_fem.fenicsx_payload`: the scikit-fem reference's mesh of the same nodes and the problem's
expressions as text) and the solution comes back as nodal arrays and a record, turned here into the same
:class:`~ctmrpim.result.Result` as every method's (``summary.json``, ``result.vtu``).

Where the interpreter or dolfinx is missing, or dolfinx is a release the worker was not written for, the
solve is refused with one line saying what to install (exit status 2 on the command line).
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import tempfile
import time
from functools import cache
from pathlib import Path

import numpy as np

from ctmrpim.errors import ConvergenceError, ProblemError
from ctmrpim.methods import SolutionMethod
from ctmrpim.problem.case import Case
from ctmrpim.result import Result, out_of_plane_stress, probe_errors
from ctmrpim.run_options import RunOptions
from ctmrpim.timing import Timer
from reference_fem.fenicsx_payload import ELEMENTS, check_masks, payload

#: environment variable naming the interpreter that has dolfinx
PYTHON_VARIABLE = "CTMRPIM_FENICSX_PYTHON"
DEFAULT_PYTHON = "/usr/bin/python3"
WORKER = Path(__file__).resolve().with_name("fenicsx_worker")
#: what the refusal tells the user to install
INSTALL = ("apt-get install python3-dolfinx (Debian 12: dolfinx 0.5 for /usr/bin/python3), or set "
           f"{PYTHON_VARIABLE} to a Python that imports dolfinx 0.5")
#: environment variables the worker keeps (the JIT cache lives under HOME or XDG_CACHE_HOME); nothing else of the
#: project's environment (VIRTUAL_ENV, PYTHONPATH ...) reaches it
KEPT = ("HOME", "LANG", "LC_ALL", "TMPDIR", "XDG_CACHE_HOME", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS")
#: seconds the version check may take (importing dolfinx takes about one)
VERSION_TIMEOUT = 120.0
#: the worker's exit status for each kind of failure (reference_fem/fenicsx_worker/__main__.py)
MISSING, VERSION, PROBLEM, CONVERGENCE = 3, 4, 5, 6


def interpreter() -> str:
    """The interpreter the worker runs on: ``$CTMRPIM_FENICSX_PYTHON`` or ``/usr/bin/python3`` (a relative path taken
    from the current folder, a bare name from PATH: the worker runs in a temporary folder)."""
    python = os.environ.get(PYTHON_VARIABLE) or DEFAULT_PYTHON
    return os.path.abspath(python) if os.sep in python else (shutil.which(python) or python)


def _environment() -> dict[str, str]:
    env = {k: os.environ[k] for k in KEPT if k in os.environ}
    env["PATH"] = "/usr/local/bin:/usr/bin:/bin"      # the C compiler of dolfinx's JIT, not the venv's bin
    return env


def _refusal(why: str) -> ProblemError:
    return ProblemError(f"fenicsx needs FEniCSx (dolfinx 0.5): {why}; install it with {INSTALL}", key="--solver")


def _run(args: list[str], cwd: str, timeout: float | None = None) -> subprocess.CompletedProcess:
    python = interpreter()
    try:
        return subprocess.run([python, "-I", str(WORKER), *args], cwd=cwd, env=_environment(), capture_output=True,
                              text=True, check=False, timeout=timeout)
    except OSError as exc:       # no such interpreter, or not executable
        raise _refusal(f"{python} cannot be run ({exc.strerror})") from None
    except subprocess.TimeoutExpired:
        raise _refusal(f"{python} did not answer within {timeout:g} s") from None


@cache
def versions() -> dict[str, str]:
    """The versions the worker finds (dolfinx, ufl, petsc4py, python); a ProblemError saying what to install
    where dolfinx is missing or unsupported. Starts the interpreter once per process (about a second)."""
    with tempfile.TemporaryDirectory(prefix="ctmrpim-fenicsx-") as tmp:
        done = _run(["--version"], tmp, timeout=VERSION_TIMEOUT)
    if done.returncode != 0:
        raise _refusal(_last_line(done.stderr) or f"the worker exited with status {done.returncode}")
    return json.loads(done.stdout)


def unavailable() -> str | None:
    """Why ``--solver fenicsx`` cannot run here (the refusal's text), or None where it can."""
    try:
        versions()
    except ProblemError as exc:
        return exc.message
    return None


def _last_line(text: str) -> str:
    lines = [line for line in text.strip().splitlines() if line.strip()]
    return lines[-1].removeprefix("fenicsx worker: ") if lines else ""


def run_worker(spec: dict, arrays: dict[str, np.ndarray]) -> tuple[dict, dict[str, np.ndarray], float]:
    """Run the worker on ``spec`` (problem.json) and ``arrays`` (arrays.npz): its record, its nodal arrays and
    the wall time of the whole run (interpreter start to exit)."""
    with tempfile.TemporaryDirectory(prefix="ctmrpim-fenicsx-") as tmp:
        src, out = Path(tmp, "in"), Path(tmp, "out")
        src.mkdir()
        (src / "problem.json").write_text(json.dumps(spec))
        np.savez(src / "arrays.npz", **arrays)
        start = time.perf_counter()
        done = _run([str(src), str(out)], tmp)
        wall = time.perf_counter() - start
        if done.returncode != 0:
            _raise(done, out)
        record = json.loads((out / "result.json").read_text())
        with np.load(out / "result.npz") as data:
            nodal = {k: data[k] for k in data.files}
    return record, nodal, wall


def _raise(done: subprocess.CompletedProcess, out: Path) -> None:
    """The error of a failed worker run: refusal, problem, non-convergence, or (any other status) a bug."""
    error = json.loads((out / "error.json").read_text()) if (out / "error.json").exists() else {}
    message = error.get("message") or _last_line(done.stderr)
    if done.returncode in (MISSING, VERSION):
        raise _refusal(message)
    if done.returncode == PROBLEM:
        raise ProblemError(f"FEniCSx: {message}")
    if done.returncode == CONVERGENCE:
        raise ConvergenceError(f"FEniCSx: {message}", key="loading", history=error.get("history", []))
    raise RuntimeError(f"the FEniCSx worker failed (exit status {done.returncode}):\n{done.stderr[-4000:]}")


def solve_fenicsx(case: Case, element: str | None, options: RunOptions) -> Result:
    """Solve ``case`` with dolfinx on the scikit-fem reference's mesh of its nodes with ``element``."""
    timer = Timer()
    element = element or ELEMENTS[0]
    problem = case.problem
    with timer.measure("mesh"):
        spec, arrays, fm = payload(case, element)
    record, nodal, wall = run_worker(spec, arrays)
    inside = record["timings"]
    for phase in ("import", "mesh", "setup", "assembly", "solve", "postprocess"):
        timer.add("fenicsx_" + phase, inside.get(phase, 0.0))
    # interpreter start and exit, file exchange: the bridge's own cost beyond the worker's phases
    timer.add("bridge", wall - sum(inside.values()))
    with timer.measure("read_back"):
        check_masks(case, fm, nodal["masks"])
    probes = record["probes"]
    errors = record["errors"]
    if problem.exact is not None:
        errors["probes"] = probe_errors(problem, probes)
    stress = nodal["stress"]
    tag = "-tl" if problem.analysis == "quasi-static" else ""
    return Result(
        method=f"fenicsx-{element}{tag}", points=fm.mesh.p.T.copy(), u=nodal["u"], stress=stress,
        stress_zz=nodal["stress_zz"] if "stress_zz" in nodal else out_of_plane_stress(problem, stress),
        cells=[(fm.cell_type, fm.cells)], probes=probes, errors=errors, counts=record["counts"],
        timings=timer.total(), history=record.get("history", []),
        parameters={**case.resolved, "derived": {"d_c": fm.d_c, "element": element}},
        defaults=list(case.defaults),
        outcome={"strain_energy": record["strain_energy"],
                 "fenicsx": {**record["versions"], "interpreter": interpreter()}})


METHOD = SolutionMethod("fenicsx", solve_fenicsx, ELEMENTS,
                        description="FEniCSx (dolfinx 0.5, system Python) on the same mesh as fem (Q1, P1, P2, Q2, P3)")
