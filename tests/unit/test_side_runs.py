"""The report's side runs (figures that need fields, the explicit conservation measures) give the same results and
progress lines in a process of their own, beside the sweep, as in the report's process."""
from __future__ import annotations

import os

import pytest

from studies.report import side_runs


def _fake_runs(quick, out_dir, progress):
    progress(f"run in {'quick' if quick else 'full'} mode into {out_dir.name}")
    return {"pid": os.getpid(), "sum": sum(range(10))}


@pytest.fixture
def fake(monkeypatch):
    monkeypatch.setattr(side_runs, "RUNS", {"first": side_runs.SideRun(_fake_runs, "demo", ("first",)),
                                           "second": side_runs.SideRun(lambda q, o, p: (p("second"), 42)[1], "demo",
                                                                       ("second",))})
    monkeypatch.setattr(side_runs, "warm_up", lambda: None)   # no solver needed here


@pytest.mark.parametrize("parallel", [False, True])
def test_side_runs_give_their_results_and_replay_their_progress(fake, tmp_path, parallel) -> None:
    lines: list[str] = []
    with side_runs.SideRuns(True, tmp_path, parallel=parallel) as side:
        first = side.result("first", lines.append)
        second = side.result("second", lines.append)
    assert first["sum"] == 45 and second == 42
    assert lines == [f"run in quick mode into {tmp_path.name}", "second"]
    if side_runs.get_all_start_methods().count("fork"):
        assert (first["pid"] != os.getpid()) == parallel   # beside the sweep, not in the report's process


def test_a_side_run_that_fails_raises_in_the_report(monkeypatch, tmp_path) -> None:
    def broken(quick, out_dir, progress):
        raise ValueError("no field")

    monkeypatch.setattr(side_runs, "RUNS", {"broken": side_runs.SideRun(broken, "demo", ("broken",))})
    monkeypatch.setattr(side_runs, "warm_up", lambda: None)
    with side_runs.SideRuns(True, tmp_path, parallel=True) as side, pytest.raises(ValueError, match="no field"):
        side.result("broken", print)
