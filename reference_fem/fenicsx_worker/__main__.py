"""The FEniCSx side of the bridge (:mod:`reference_fem.fenicsx`), run by the system interpreter, never imported by
the project (a folder without ``__init__.py``, installed as package data):

    /usr/bin/python3 -I reference_fem/fenicsx_worker IN OUT    solve IN/problem.json + IN/arrays.npz with dolfinx
                                                               into OUT/result.json + OUT/result.npz
    /usr/bin/python3 -I reference_fem/fenicsx_worker --version the versions as JSON (the bridge's check)

Its modules import only the standard library, numpy and FEniCSx (they find each other by their bare names,
``fx_*``), so nothing of ctmrpim, scikit-fem or the project's virtual environment takes part in the solve: the
problem arrives as plain data, its expressions as the text the user wrote (``fx_expressions`` makes them UFL).

Exit status 0 on success; otherwise ``OUT/error.json`` says why (kind "missing": dolfinx cannot be imported,
"version": a dolfinx the worker was not written for, "problem": the input cannot be solved as posed,
"convergence": Newton gave up, with the history) and the status is 3, 4, 5 or 6.
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

START = time.perf_counter()
# -I leaves the script's folder off sys.path (and the project's environment out): the fx_* modules are found here
sys.path.insert(0, str(Path(__file__).resolve().parent))

#: the dolfinx releases this worker is written for (0.6 changed the mesh, form and PETSc interfaces)
SUPPORTED = "0.5."
EXIT = {"missing": 3, "version": 4, "problem": 5, "convergence": 6}


def _fail(out: Path | None, kind: str, message: str, **extra) -> None:
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        (out / "error.json").write_text(json.dumps({"kind": kind, "message": message, **extra}))
    print(f"fenicsx worker: {kind}: {message}", file=sys.stderr)
    sys.exit(EXIT[kind])


def _import_dolfinx(out: Path | None) -> str:
    """dolfinx's version, after checking that it imports and is one this worker supports."""
    try:
        import dolfinx
    except ImportError as exc:
        _fail(out, "missing", f"dolfinx cannot be imported by {sys.executable} ({exc})")
    if not dolfinx.__version__.startswith(SUPPORTED):
        _fail(out, "version", f"dolfinx {dolfinx.__version__} found; the worker supports {SUPPORTED}x")
    return dolfinx.__version__


def _versions(dolfinx: str) -> dict[str, str]:
    import basix
    import petsc4py
    import ufl
    return {"dolfinx": dolfinx, "basix": basix.__version__, "ufl": ufl.__version__, "petsc4py": petsc4py.__version__,
            "python": sys.version.split()[0]}


def main(argv: list[str]) -> None:
    if argv == ["--version"]:
        print(json.dumps(_versions(_import_dolfinx(None))))
        return
    src, out = Path(argv[0]), Path(argv[1])
    version = _import_dolfinx(out)
    import fx_hyperelastic
    import fx_linear
    import fx_mesh
    import numpy as np
    from fx_expressions import TranslationError
    from fx_problem import WorkerProblem

    timings = {"import": time.perf_counter() - START}
    spec = json.loads((src / "problem.json").read_text())
    arrays = np.load(src / "arrays.npz")
    start = time.perf_counter()
    md = fx_mesh.build(arrays["points"], arrays["cells"], spec["cell_type"])
    timings["mesh"] = time.perf_counter() - start
    solver = fx_linear if spec["analysis"] == "linear" else fx_hyperelastic
    try:
        record, nodal = solver.solve(md, spec, timings)
    except (WorkerProblem, TranslationError, ValueError) as exc:
        _fail(out, "problem", str(exc))
    except fx_hyperelastic.NotConverged as exc:
        _fail(out, "convergence", str(exc), history=exc.history)
    record.update(versions=_versions(version), timings=timings)
    out.mkdir(parents=True, exist_ok=True)
    np.savez(out / "result.npz", **nodal)
    (out / "result.json").write_text(json.dumps(record))


if __name__ == "__main__":
    main(sys.argv[1:])
