"""The studies in quick mode, run through the run's study cache (the ``sweep`` fixture of tests/conftest.py)."""
from __future__ import annotations

import pytest


class QuickStudies:
    """Each study's quick table, run on first use (its CSV and PNG written to ``reports``); ``all()`` runs the
    rest."""

    def __init__(self, sweep, reports) -> None:
        self.sweep, self.reports, self.tables = sweep, reports, {}

    def __getitem__(self, name: str):
        import studies

        if name not in self.tables:
            self.tables[name] = studies.run(name, True, self.reports, self.sweep, progress=lambda *_: None)
        return self.tables[name]

    def all(self) -> dict:
        import studies

        return {name: self[name] for name in studies.NAMES}


@pytest.fixture(scope="session")
def quick_studies(sweep, tmp_path_factory) -> QuickStudies:
    return QuickStudies(sweep, tmp_path_factory.mktemp("studies") / "reports")


@pytest.fixture(scope="session")
def tables(quick_studies) -> dict:
    """Every study's quick table."""
    return quick_studies.all()
