"""The main job, ``ctmrpim report --quick``: every study in quick mode, the deformed shapes, each number
checked against the tolerances table, written as REPORT.md with its figures."""
from __future__ import annotations

import pytest

import studies

pytestmark = pytest.mark.slow


def test_quick_report(tables, sweep, tmp_path) -> None:
    """The main job: every section and figure is written and every check passes (the studies' cases
    come from the shared cache, so this only adds the report's own work)."""
    from studies.report import make_report

    path = make_report(quick=True, out_dir=tmp_path, sweep=sweep, progress=lambda *_: None)
    text = path.read_text()
    assert "FAIL" not in text
    for name in [*studies.NAMES, "deformed_shapes"]:
        assert f"({name}.png)" in text and (tmp_path / f"{name}.png").is_file()
    assert sweep.computed == 0
