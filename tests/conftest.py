"""Shared by every folder: tests/ on sys.path (the helper modules clouds.py and verify.py), the folder markers
(unit, verification, system), and the solves more than one test needs, each done once per run."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

pytest_plugins = ["solve_audit"]   # pytest --audit-solves

FOLDERS = ("unit", "verification", "system")


@pytest.hookimpl(tryfirst=True)   # before -m selects
def pytest_collection_modifyitems(items) -> None:
    here = Path(__file__).parent
    for item in items:
        folder = item.path.relative_to(here).parts[0]
        if folder in FOLDERS:
            item.add_marker(folder)


class Solutions:
    """``solutions(case_or_target, overrides, method, element)``: the Result of each distinct solve (same
    resolved input, method and element), computed on first use through :func:`ctmrpim.methods.solve` and
    shared for the rest of the run. Shared results are read, never changed."""

    def __init__(self) -> None:
        from ctmrpim.methods import solve

        self.results: dict[str, object] = {}
        self._solve = solve     # the real one, also while a test stands this in for it

    def __call__(self, case, overrides=(), method: str = "ctm-rpim", element: str | None = None):
        from ctmrpim import benchmarks, methods

        if isinstance(case, str):
            case = benchmarks.load(case, list(overrides))
        element = methods.element_of(methods.get(method), element)
        key = json.dumps([case.resolved, method, element], sort_keys=True, default=str)
        if key not in self.results:
            self.results[key] = self._solve(case, method, element)
        return self.results[key]

    def solve(self, case, method: str = "ctm-rpim", element: str | None = None, **options):
        """A stand-in for :func:`ctmrpim.methods.solve` (the command line's and the README's) that shares these
        results; an explicit run (written to ``out`` as it goes) is always solved."""
        if case.problem.analysis == "explicit":
            return self._solve(case, method, element, **options)
        return self(case, method=method, element=element)


@pytest.fixture(scope="session")
def solutions() -> Solutions:
    return Solutions()


@pytest.fixture(scope="session")
def sweep(tmp_path_factory):
    """The study cache of the run (:class:`studies.sweep.Sweep`, two worker processes): the studies' cases, and
    the verification cases that are also a study's, each solved once."""
    from studies.sweep import Sweep

    return Sweep(tmp_path_factory.mktemp("sweeps"), workers=2, progress=False)


@pytest.fixture(scope="session")
def study_cases(sweep):
    """``study_cases(*specs)``: the summary.json of each CaseSpec (target, overrides, solver, element), solved
    through the run's study cache, the cases not cached yet in parallel. For a verification case that is also a
    quick study's, so that it is solved once when the studies run too."""
    def summaries(*specs) -> list[dict]:
        outcomes = sweep.run(specs, desc="verification")
        for o in outcomes:
            assert o.status == "ok", f"{o.spec}: {o.error}"
        return [o.summary for o in outcomes]
    return summaries
