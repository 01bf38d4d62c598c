"""A study whose every case fails says so in one error and writes nothing (no empty table, no traceback
from a figure without data)."""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from ctmrpim.errors import ProblemError
from studies.base import run_study
from studies.sweep import CaseSpec, Sweep


def test_a_study_whose_cases_all_fail_is_an_error(tmp_path: Path) -> None:
    module = SimpleNamespace(NAME="broken", specs=lambda quick: [CaseSpec("cantilever", ("method.support_radius=0.5",))],
                             figure=lambda df: pytest.fail("no figure of nothing"))
    with pytest.raises(ProblemError, match=r"study broken: all 1 cases failed \(first: status 'error', .*support_radius"):
        run_study(module, out_dir=tmp_path / "reports", sweep=Sweep(tmp_path / "cache"), progress=lambda s: None)
    assert not (tmp_path / "reports").exists()
