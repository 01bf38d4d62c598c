"""``--solver fenicsx``: the bridge to dolfinx in the system interpreter. Its refusals run everywhere; the live
comparisons with scikit-fem run where the bridge finds dolfinx 0.5 (``apt-get install python3-dolfinx``; CI
installs it) and are skipped with the reason elsewhere, dolfinx being optional."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from verify import check

from reference_fem import fenicsx
from reference_fem import fenicsx_golden as golden

CTMRPIM = str(Path(sys.executable).with_name("ctmrpim"))
WHY = fenicsx.unavailable()
live = pytest.mark.skipif(WHY is not None, reason=f"dolfinx not available to the bridge: {WHY}")
#: a few cases on every run (each solver path, a Delaunay cloud, a user file); all of them in the slow tier
FAST = ("cantilever-p2", "cantilever-cloud-p1", "plate-hole-p2", "bracket-p2", "tip-load-q1")
#: a user's problem file without CTM-RPIM's [method] table (a benchmark's would add a warning line)
BRACKET = str(golden.FOLDER / "bracket.toml")


def _run(*args: str, env: dict | None = None, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([CTMRPIM, "run", *args], capture_output=True, text=True, env=env, cwd=cwd)


def _env(python: str) -> dict:
    import os
    return {**os.environ, fenicsx.PYTHON_VARIABLE: python}


def test_refused_without_an_interpreter(tmp_path: Path) -> None:
    done = _run(BRACKET, "--solver", "fenicsx", "--element", "p2", "--out", str(tmp_path / "out"),
                env=_env(str(tmp_path / "no-python")))
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "apt-get install python3-dolfinx" in lines[0], done.stderr
    assert not (tmp_path / "out" / "summary.json").exists()


def test_refused_where_the_interpreter_has_no_dolfinx(tmp_path: Path) -> None:
    """The project's own interpreter has no dolfinx (and -I keeps its environment out)."""
    done = _run(BRACKET, "--solver", "fenicsx", "--element", "p1", "--out", str(tmp_path / "out"),
                env=_env(sys.executable))
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and "dolfinx cannot be imported" in done.stderr, done.stderr


def test_refused_for_an_unsupported_dolfinx(tmp_path: Path) -> None:
    """An interpreter whose dolfinx is a release the worker was not written for."""
    fake = tmp_path / "python-with-dolfinx-0.9"
    fake.write_text(f"#!/bin/sh\nexec {sys.executable} -c \"import sys, types; sys.modules['dolfinx'] = "
                    "types.SimpleNamespace(__version__='0.9.0'); sys.argv = sys.argv[2:]; import runpy; "
                    "runpy.run_path(sys.argv[0], run_name='__main__')\" \"$@\"\n")
    fake.chmod(0o755)
    done = _run(BRACKET, "--solver", "fenicsx", "--element", "p2", "--out", str(tmp_path / "out"),
                env=_env(str(fake)))
    assert done.returncode == 2
    assert "dolfinx 0.9.0 found; the worker supports 0.5.x" in done.stderr and "apt-get install" in done.stderr


def test_analyses_it_does_not_solve_are_refused_before_starting_it(tmp_path: Path) -> None:
    done = _run("slope", "--solver", "fenicsx", "--element", "p2", "--out", str(tmp_path / "out"),
                env=_env(str(tmp_path / "no-python")))
    assert done.returncode == 2
    assert "solves linear elasticity" in done.stderr and "apt-get" not in done.stderr


def _compare(gc: golden.GoldenCase, solutions) -> None:
    ours = golden.record(solutions(gc.load(), method="fenicsx", element=gc.element))
    diff = golden.differences(ours, golden.record(solutions(gc.load(), method="fem", element=gc.element)))
    kind = "linear" if gc.linear else "tip-load"
    check(f"fenicsx-{kind}-displacement", max(diff["u_nodes"], diff["u_probes"]))
    check(f"fenicsx-{kind}-energy", diff["energy"])
    check(f"fenicsx-{kind}-stress", diff["stress_probes"])
    if "errors" in diff:
        check("fenicsx-linear-errors", diff["errors"])
    # and the golden file is what this dolfinx computes now
    stored = golden.differences(ours, golden.read(gc))
    check(f"fenicsx-{kind}-displacement", stored["u_nodes"])


@live
@pytest.mark.parametrize("name", FAST)
def test_live_fenicsx_matches_scikit_fem(name: str, solutions) -> None:
    _compare(golden.BY_NAME[name], solutions)


@live
@pytest.mark.slow
@pytest.mark.parametrize("name", [gc.name for gc in golden.CASES if gc.name not in FAST])
def test_live_fenicsx_matches_scikit_fem_every_case(name: str, solutions) -> None:
    _compare(golden.BY_NAME[name], solutions)


@live
def test_cli_writes_the_same_outputs(tmp_path: Path) -> None:
    done = _run("cantilever", "--solver", "fenicsx", "--element", "p2", "--set", "nodes.grid=[17, 5]", "--quiet",
                "--out", str(tmp_path / "out"))
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["method"] == "fenicsx-p2" and summary["fenicsx"]["dolfinx"].startswith("0.5.")
    assert summary["counts"]["nodes"] == 85 and summary["errors"]["probes"]["tip"]["uy"] < 1e-4
    assert {"fenicsx_import", "bridge", "total"} <= set(summary["timings"])
    assert (tmp_path / "out" / "result.vtu").stat().st_size > 0


@live
def test_q2_on_the_cantilever(solutions) -> None:
    """Q2, which the scikit-fem reference lacks: better than P2 on the same grid, and exact at the root."""
    case = golden.BY_NAME["cantilever-p2"].load()
    q2 = solutions(case, method="fenicsx", element="q2")
    p2 = solutions(case, method="fem", element="p2")
    assert q2.method == "fenicsx-q2" and q2.cells[0][0] == "quad"
    assert q2.errors["energy"] < p2.errors["energy"]
    root = q2.points[:, 0] == 0.0
    assert np.allclose(q2.u[root], case.problem.exact.displacement(*q2.points[root].T), rtol=0, atol=1e-15)


@live
def test_p3_reproduces_the_cantilevers_cubic_solution(solutions) -> None:
    """The Timoshenko field is a cubic polynomial: P3 holds it exactly, so every load, prescribed value and
    norm the worker translated from the problem's text is checked to round-off."""
    result = solutions(golden.BY_NAME["cantilever-p2"].load(), method="fenicsx", element="p3")
    assert result.method == "fenicsx-p3"
    assert result.errors["l2"] < 1e-10 and result.errors["energy"] < 1e-10
    assert result.errors["probes"]["tip"]["uy"] < 1e-10


def test_q2_and_p3_name_themselves_when_refused(tmp_path: Path) -> None:
    done = _run("cantilever", "--solver", "fenicsx", "--element", "q2", "--set", "nodes.spacing=2.0",
                "--out", str(tmp_path / "out"), env=_env(str(tmp_path / "no-python")))
    assert done.returncode == 2 and "q2 needs a rectangular body" in done.stderr
