"""``pytest --audit-solves``: count every solve of the run by (resolved input, solver, arguments) and list those
done more than once, so that an expensive solve is shared through a fixture or the study cache instead.

The solvers each method dispatches to are wrapped before the test modules are imported; each call appends
one line to a file, so that solves in the study sweep's forked worker processes count too (a console script
run in a subprocess, or a Dask worker, does not). The sweep's per-process warm-up solves are left out.
"""
from __future__ import annotations

import functools
import importlib
import json
import os
import shutil
import sys
import tempfile
from collections import Counter
from pathlib import Path

#: (module, function): the solvers behind ``ctmrpim.methods.solve``, each called with the case first
SOLVERS = [("ctmrpim.solvers.linear_static", "solve_ctmrpim"),
           ("ctmrpim.solvers.total_lagrangian", "solve_total_lagrangian"),
           ("ctmrpim.solvers.updated_lagrangian", "solve_updated_lagrangian"),
           ("ctmrpim.solvers.elastoplastic", "solve_elastoplastic"),
           ("ctmrpim.solvers.explicit.run", "solve_explicit"),
           ("reference_fem.solve", "solve_fem"),
           ("reference_fem.hyperelastic", "solve_fem_hyperelastic"),
           ("reference_fem.elastoplastic", "solve_fem_elastoplastic")]
_log: Path | None = None
_paused = False


def pytest_addoption(parser) -> None:
    parser.addoption("--audit-solves", action="store_true",
                     help="list every solve done more than once in this run (same resolved input and solver)")


def _key(name: str, case, args: tuple, kwargs: dict) -> str:
    plain = [a for a in args if a is None or isinstance(a, (str, int, float))]   # element, refine; not paths
    plain += [f"{k}={v}" for k, v in sorted(kwargs.items()) if v is None or isinstance(v, (str, int, float))]
    return json.dumps([name, plain, case.resolved], sort_keys=True, default=str)


def _audited(name: str, solver):
    @functools.wraps(solver)
    def wrapper(case, *args, **kwargs):
        if not _paused:
            line = json.dumps({"key": _key(name, case, args, kwargs), "test": os.environ.get("PYTEST_CURRENT_TEST", "")})
            with open(_log, "a") as f:
                f.write(line + "\n")
        return solver(case, *args, **kwargs)
    return wrapper


def _unaudited(warm_up):
    @functools.wraps(warm_up)
    def wrapper():
        global _paused
        _paused = True
        try:
            warm_up()
        finally:
            _paused = False
    return wrapper


def pytest_configure(config) -> None:
    global _log
    if not config.getoption("audit_solves"):
        return
    _log = Path(tempfile.mkdtemp(prefix="solve-audit-")) / "solves.jsonl"
    _log.touch()
    for module, name in SOLVERS:
        original = getattr(importlib.import_module(module), name)
        wrapped = _audited(name, original)
        for m in list(sys.modules.values()):           # the module and those that imported the name already
            if getattr(m, name, None) is original:
                setattr(m, name, wrapped)
    sweep = importlib.import_module("studies.sweep")
    sweep._warm_up = _unaudited(sweep._warm_up)


def pytest_terminal_summary(terminalreporter, config) -> None:
    if _log is None:
        return
    records = [json.loads(line) for line in _log.read_text().splitlines()]
    shutil.rmtree(_log.parent, ignore_errors=True)
    counts = Counter(r["key"] for r in records)
    write = terminalreporter.write_line
    terminalreporter.section("solve audit")
    write(f"{len(records)} solves, {len(counts)} distinct; repeated: {sum(1 for n in counts.values() if n > 1)}")
    for key, n in counts.most_common():
        if n < 2:
            break
        name, plain, resolved = json.loads(key)
        overrides = {k: resolved.get(k) for k in ("nodes", "parameters")}
        write(f"{n}x {name}{tuple(plain)} {resolved['problem']['name']} {json.dumps(overrides)[:200]}")
        for test in sorted({r["test"].rsplit(" (", 1)[0] for r in records if r["key"] == key}):
            write(f"      {test}")
