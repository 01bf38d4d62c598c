"""Explicit runs through the command line: a run killed (SIGKILL, so in a subprocess) and resumed from its
checkpoint, a resume of another problem refused, a diverging run stopped naming what, where and when (these
two in-process)."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import meshio
import numpy as np
import pytest

from ctmrpim import benchmarks
from ctmrpim.cli import main
from ctmrpim.errors import ProblemError
from ctmrpim.solvers.explicit.run import solve_explicit
from ctmrpim.solvers.explicit.state import input_key


def _positions(folder: Path) -> np.ndarray:
    m = meshio.read(folder / "result.vtu")
    return m.points[:, :2] + m.point_data["u"][:, :2]


RESUME = ["nodes.grid=[16, 9]", "explicit.duration=0.06", "explicit.checkpoint_every=40",
          "explicit.save_every=0.02"]


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "ctmrpim.cli", *args]


def test_killed_run_resumes_to_the_same_state(tmp_path):
    """SIGKILL after the first checkpoints, then --resume: the same final state as a run left alone."""
    sets = [a for s in RESUME for a in ("--set", s)]
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    assert main(["run", "column-collapse", *sets, "--out", str(whole), "--quiet"]) == 0
    proc = subprocess.Popen(_cli("run", "column-collapse", *sets, "--out", str(killed), "--quiet"))
    checkpoint = killed / "checkpoint.npz"
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None:
        if checkpoint.is_file() and json.loads(str(np.load(checkpoint)["meta"]))["step"] >= 80:
            break
        time.sleep(0.01)
    assert proc.poll() is None, "the run ended before it could be killed: lengthen RESUME"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert not (killed / "summary.json").exists()
    assert main(["run", "column-collapse", *sets, "--out", str(killed), "--resume", "--quiet"]) == 0
    diff = np.abs(_positions(whole) - _positions(killed)).max()
    assert diff <= 1e-8 * 0.2
    a, b = (json.loads((f / "summary.json").read_text())["dynamics"] for f in (whole, killed))
    assert a["steps"] == b["steps"] and a["rebuilds"] == b["rebuilds"]
    pvd = (killed / "result.pvd").read_text()
    assert pvd.count("<DataSet") == len(list((killed / "series").glob("*.vtu")))


def test_resume_needs_the_same_problem(tmp_path):
    case = benchmarks.load("column-collapse", RESUME)
    with pytest.raises(ProblemError, match="no checkpoint"):
        solve_explicit(case, tmp_path, resume=True)
    other = benchmarks.load("column-collapse", RESUME + ["material.phi=25"])
    assert input_key(case) != input_key(other)


def test_divergence_names_what_where_and_when(tmp_path, capsys):
    """A time step far above the stable one: the run stops with the step, time and place in one line, exit 3
    (the input was accepted, the solve did not converge), the status and the summary say "not converged"
    with the history up to there, and no result.vtu is written."""
    out = tmp_path / "bad"
    code = main(["run", "column-collapse", "--set", "nodes.grid=[16, 9]", "--set", "explicit.dt=5e-3",
                 "--set", "explicit.initial=\"none\"", "--out", str(out), "--quiet"])
    stderr = capsys.readouterr().err
    assert code == 3
    assert "Traceback" not in stderr and len(stderr.splitlines()) == 1
    assert stderr.startswith("ctmrpim: not converged: ") and "step" in stderr and "t = " in stderr
    assert not (out / "result.vtu").exists()
    status = json.loads((out / "status.json").read_text())
    summary = json.loads((out / "summary.json").read_text())
    assert status["state"] == summary["status"] == "not converged" and status["exit_status"] == 3
    assert "t = " in summary["error"] and summary["history"]
