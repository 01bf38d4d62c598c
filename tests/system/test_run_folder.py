"""One run per output folder, its status record, strict JSON, the exit statuses 3 and 130, the default
folder, ``--version`` and the progress display: ``ctmrpim.cli.main`` in-process, and the console script in
a subprocess where a real signal or the real stderr matters."""
from __future__ import annotations

import io
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from ctmrpim import methods, progress
from ctmrpim.cli import main
from ctmrpim.io.checkpoint import load_checkpoint, save_checkpoint
from ctmrpim.timing import Timer
from ctmrpim.version import __version__

SCRIPT = Path(sys.executable).with_name("ctmrpim")
#: a quick quasi-static run with a series (four increments)
QUASI_STATIC = ["tip-load", "--set", "nodes.grid=[17,3]", "--set", "loading.steps=4"]
#: the same, Newton capped so that the third increment fails with no cut-back left
NOT_CONVERGING = QUASI_STATIC + ["--set", "loading.max_cutbacks=0", "--set", "loading.max_iterations=8"]
LINEAR = ["cantilever", "--set", "nodes.grid=[17,5]"]
#: dynamic relaxation of a strong Mohr-Coulomb column under its own weight; 50 steps are too few to come to rest
RELAXATION = ["self-weight", "--set", 'problem.analysis="dynamic"', "--set", 'material.model="mohr-coulomb"',
              "--set", "material.c=1e9", "--set", "material.phi=30", "--set", "dynamic.steps=50",
              "--set", "dynamic.record_every=20"]
#: the explicit run the signal tests stop: it cannot come to rest before the signal (explicit.rest = 1e-12)
EXPLICIT = ["column-collapse", "--set", "nodes.grid=[16,9]", "--set", "explicit.duration=5", "--set",
            "explicit.checkpoint_every=20", "--set", "explicit.rest=1e-12"]
#: a linear problem whose exact stresses are zero: its relative energy error is x/0
SHIFT = """
[problem]
name = "shift"
analysis = "linear"
plane = "stress"
[geometry]
add = [{ rectangle = [0, 0, 2, 1] }]
[nodes]
grid = [9, 5]
[material]
model = "linear-elastic"
E = 1e5
nu = 0.3
[[constraint]]
where = "x == 0 or x == 2 or y == 0 or y == 1"
ux = "0.01"
uy = "0"
[exact]
ux = "0.01"
uy = "0"
sxx = "0"
syy = "0"
sxy = "0"
"""


def _cli(*args: str) -> list[str]:
    return [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "ctmrpim.cli"]


def _run(capsys, *args: str) -> tuple[int, str, str]:
    capsys.readouterr()
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def _json(path: Path) -> dict:
    """A JSON file read strictly: NaN or Infinity in it fail the test."""
    def refuse(name: str) -> None:
        raise AssertionError(f"{path} holds {name}: not strict JSON")
    return json.loads(path.read_text(), parse_constant=refuse)


def test_a_new_run_removes_the_earlier_runs_files_only(tmp_path, capsys) -> None:
    """A quasi-static run (series, result.pvd), then a linear one into the same folder: no state of the first
    is left, a hidden temporary file of a killed write goes too, and the user's own files stay."""
    out = tmp_path / "out"
    assert _run(capsys, "run", *QUASI_STATIC, "--out", str(out), "--quiet")[0] == 0
    assert len(list((out / "series").glob("step_*.vtu"))) == 4 and (out / "result.pvd").is_file()
    (out / "notes.txt").write_text("mine")
    (out / "series" / "mine.txt").write_text("mine too")
    (out / ".result.vtu.k1ll3d00.tmp").write_text("half a file")
    assert _run(capsys, "run", *LINEAR, "--out", str(out), "--quiet")[0] == 0
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt", "result.vtu", "series", "status.json",
                                                     "summary.json"]
    assert [p.name for p in (out / "series").iterdir()] == ["mine.txt"]
    assert _json(out / "summary.json")["parameters"]["problem"]["analysis"] == "linear"
    status = _json(out / "status.json")
    assert status["state"] == "ok" and status["exit_status"] == 0 and status["version"] == __version__
    assert status["outputs"] == ["result.vtu", "summary.json"] and status["series_files"] == 0
    assert status["command"].startswith("ctmrpim run cantilever") and status["started"] <= status["finished"]


def test_fewer_increments_leave_no_extra_steps(tmp_path, capsys) -> None:
    out = tmp_path / "out"
    assert _run(capsys, "run", *QUASI_STATIC, "--out", str(out), "--quiet")[0] == 0
    assert _run(capsys, "run", *QUASI_STATIC, "--set", "loading.steps=2", "--out", str(out), "--quiet")[0] == 0
    assert sorted(p.name for p in (out / "series").iterdir()) == ["step_0001.vtu", "step_0002.vtu"]
    assert (out / "result.pvd").read_text().count("<DataSet") == 2


def test_the_status_says_running_while_the_solve_runs(tmp_path, capsys, monkeypatch) -> None:
    """The status record is written before the solve and the earlier run's files are gone by then."""
    out = tmp_path / "out"
    assert _run(capsys, "run", *LINEAR, "--out", str(out), "--quiet")[0] == 0
    seen = {}
    solve = methods.solve

    def spy(case, *args, **kw):
        seen["files"] = sorted(p.name for p in out.iterdir())
        seen["status"] = _json(out / "status.json")
        return solve(case, *args, **kw)

    monkeypatch.setattr(methods, "solve", spy)
    assert _run(capsys, "run", *LINEAR, "--out", str(out), "--quiet")[0] == 0
    assert seen["files"] == ["status.json"]
    assert seen["status"]["state"] == "running" and seen["status"]["pid"] == os.getpid()
    assert "finished" not in seen["status"]


def test_a_folder_with_foreign_files_under_a_runs_names_is_refused(tmp_path, capsys) -> None:
    """A summary.json ctmrpim did not write is neither removed nor overwritten: one line, exit 2."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text('{"mine": true}')
    code, stdout, stderr = _run(capsys, "run", *LINEAR, "--out", str(out))
    assert code == 2 and stdout == "" and len(stderr.splitlines()) == 1
    assert "summary.json, which no ctmrpim run there wrote" in stderr
    assert sorted(p.name for p in out.iterdir()) == ["summary.json"]
    assert (out / "summary.json").read_text() == '{"mine": true}'


def test_newton_giving_up_exits_3_with_the_history(tmp_path, capsys) -> None:
    """Two increments converge, the third does not: exit 3, one line, the status and summary say "not
    converged", the summary holds the history up to there, and no result of an earlier run stays."""
    out = tmp_path / "out"
    assert _run(capsys, "run", *LINEAR, "--out", str(out), "--quiet")[0] == 0
    code, stdout, stderr = _run(capsys, "run", *NOT_CONVERGING, "--out", str(out), "--quiet")
    assert code == 3 and stdout == ""
    assert stderr.splitlines() == [stderr.strip()] and "Traceback" not in stderr
    assert stderr.startswith("ctmrpim: not converged: ") and "Newton did not converge at load factor 0.75" in stderr
    assert sorted(p.name for p in out.iterdir()) == ["status.json", "summary.json"]
    summary, status = _json(out / "summary.json"), _json(out / "status.json")
    assert summary["status"] == status["state"] == "not converged" and status["exit_status"] == 3
    assert summary["error"] == status["error"] and "loading" in summary["error"]
    assert [(h["load_factor"], h["converged"]) for h in summary["history"]] == [(0.25, True), (0.5, True),
                                                                              (0.75, False)]
    assert "tip" in summary["history"][0]          # the probe of each converged increment
    assert summary["parameters"]["loading"]["max_iterations"] == 8


def test_a_limit_load_is_an_answer_not_exit_3(tmp_path, capsys) -> None:
    """until_failure: the load that is not carried is the result (exit 0, status ok), though Newton gave up
    there after its cut-backs."""
    out = tmp_path / "out"
    code, _, _ = _run(capsys, "run", "footing", "--set", "parameters.nx=13", "--set", "parameters.ny=6", "--set",
                      "loading.steps=4", "--set", "loading.max_cutbacks=2", "--set", "parameters.q_max=2e6",
                      "--out", str(out), "--quiet")
    s = _json(out / "summary.json")
    assert code == 0 and "status" not in s and _json(out / "status.json")["state"] == "ok"
    assert s["limit_pressure"]["failed"] is not None


@pytest.mark.filterwarnings(r"ignore:\[exact\] is not compared:UserWarning")
def test_dynamic_relaxation_not_at_rest_exits_3(tmp_path, capsys) -> None:
    """A relaxation still moving after its steps has not found the static answer: exit 3 like Newton giving
    up, its history in the summary, the last record marked, no result."""
    out = tmp_path / "out"
    code, stdout, stderr = _run(capsys, "run", *RELAXATION, "--out", str(out), "--quiet")
    assert code == 3 and stdout == "" and "Traceback" not in stderr
    last = stderr.splitlines()[-1]
    assert last.startswith("ctmrpim: not converged: ") and "dynamic.steps: dynamic relaxation did not come to rest " \
        "in 50 steps" in last and "above dynamic.tolerance = 0.0001" in last
    assert sorted(p.name for p in out.iterdir()) == ["status.json", "summary.json"]
    summary, status = _json(out / "summary.json"), _json(out / "status.json")
    assert summary["status"] == status["state"] == "not converged" and status["exit_status"] == 3
    assert [h["step"] for h in summary["history"]] == [20, 40, 50] and summary["history"][-1]["note"] == "not at rest"
    assert summary["notes"] == ["[exact] is not compared in a 'dynamic' analysis (only linear analyses report errors)"]


@pytest.mark.filterwarnings(r"ignore:\[exact\] is not compared:UserWarning")
def test_dynamic_relaxation_diverging_exits_3(tmp_path, capsys, monkeypatch) -> None:
    """Masses far below the stable ones: the relaxation blows up. Exit 3 (not 2: the input was accepted), the
    history up to the step whose forces were not finite, that record marked, no numpy warning on stderr."""
    from ctmrpim.solvers import dynamic_relaxation
    stable = dynamic_relaxation.relaxation_mass
    monkeypatch.setattr(dynamic_relaxation, "relaxation_mass", lambda system: 1e-3 * stable(system))
    out = tmp_path / "out"
    code, _, stderr = _run(capsys, "run", *RELAXATION, "--set", "dynamic.steps=2000", "--out", str(out), "--quiet")
    assert code == 3 and "Warning" not in stderr.replace("ctmrpim: warning:", "")
    assert re.search(r"dynamic: dynamic relaxation diverged at step \d+ \(non-finite forces\)", stderr)
    summary = _json(out / "summary.json")
    assert summary["status"] == "not converged" and summary["history"][-1]["note"] == "diverged: non-finite forces"
    assert summary["history"][-1]["residual"] is None     # infinite: null with a note
    assert any(n.startswith(f"history[{len(summary['history']) - 1}].residual is undefined") for n in summary["notes"])


def test_interrupted_in_process(tmp_path, capsys, monkeypatch) -> None:
    def interrupted(*args, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(methods, "solve", interrupted)
    code, stdout, stderr = _run(capsys, "run", *LINEAR, "--out", str(tmp_path / "out"))
    assert code == 130 and stderr == "ctmrpim: interrupted\n" and stdout == ""
    status = _json(tmp_path / "out" / "status.json")
    assert status["state"] == "interrupted" and status["exit_status"] == 130


def test_ctrl_c_exits_130_and_keeps_the_checkpoint(tmp_path) -> None:
    """SIGINT to the console script during an explicit run: exit 130, one line, no traceback, the status
    "interrupted", the checkpoint kept for --resume."""
    stderr = _stopped_by(signal.SIGINT, tmp_path / "out", 130)
    assert stderr.splitlines()[-1] == "ctmrpim: interrupted"


def test_sigterm_exits_143_and_keeps_the_checkpoint(tmp_path) -> None:
    """SIGTERM (kill, a batch system's time limit) ends a run as Ctrl-C does, with exit status 143: the
    status "interrupted" (not "running" for ever), the checkpoint kept, no half-written file."""
    stderr = _stopped_by(signal.SIGTERM, tmp_path / "out", 143)
    assert stderr.splitlines()[-1] == "ctmrpim: terminated (SIGTERM)"
    assert _json(tmp_path / "out" / "status.json")["error"] == "terminated (SIGTERM)"


def _default_signals() -> None:
    # a test run in the background of a non-interactive shell (CI, the fresh-checkout check) inherits SIGINT
    # ignored, and Python then keeps ignoring it: give the child the default dispositions
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_DFL)


def _stopped_by(sig: signal.Signals, out: Path, exit_status: int) -> str:
    """Send ``sig`` to the console script once its explicit run has written a checkpoint into ``out``; check the
    exit status, the status record, the checkpoint kept and that nothing is left half-written; its stderr."""
    proc = subprocess.Popen(_cli() + ["run", *EXPLICIT, "--out", str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=_default_signals)
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None and not (out / "checkpoint.npz").is_file():
        time.sleep(0.05)
    assert proc.poll() is None, proc.communicate()
    assert _json(out / "status.json")["state"] == "running"     # the explicit solver keeps the record
    proc.send_signal(sig)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == exit_status, stderr
    assert "Traceback" not in stderr and "\r" not in stderr     # stderr is a pipe: plain lines, if any
    status = _json(out / "status.json")
    assert status["state"] == "interrupted" and status["exit_status"] == exit_status
    assert (out / "checkpoint.npz").is_file() and not (out / "summary.json").exists()
    assert not [p for p in out.rglob("*.tmp")]                   # no write was left half done
    return stderr


def test_undefined_errors_are_null_with_a_note(tmp_path, capsys) -> None:
    """The exact stresses are zero: the energy-norm error is x/0. summary.json stays strict JSON, the value
    is null with a note, nothing warns, and the text summary says undefined."""
    problem = tmp_path / "shift.toml"
    problem.write_text(SHIFT)
    code, stdout, stderr = _run(capsys, "run", str(problem), "--out", str(tmp_path / "out"))
    assert code == 0 and stderr == ""
    s = _json(tmp_path / "out" / "summary.json")
    assert s["errors"]["energy"] is None and s["errors"]["l2"] < 1e-10
    assert len(s["notes"]) == 1 and s["notes"][0].startswith("errors.energy is undefined (NaN)")
    assert "energy undefined" in stdout


def test_checkpoint_metadata_is_strict_and_keeps_infinities(tmp_path) -> None:
    meta = {"stage_residual": float("inf"), "dt_range": [float("inf"), 0.0], "t": 0.5}
    save_checkpoint(tmp_path, "k", meta, {"x": np.zeros(2)})
    with np.load(tmp_path / "checkpoint.npz") as data:
        json.loads(str(data["meta"]), parse_constant=lambda c: pytest.fail(f"{c} in the metadata"))
    back, arrays = load_checkpoint(tmp_path, "k")
    assert back["stage_residual"] == float("inf") and back["dt_range"] == [float("inf"), 0.0] and back["t"] == 0.5


def test_default_folders_of_two_files_with_one_name_differ(tmp_path, capsys, monkeypatch) -> None:
    """Two problem files with the same file name and problem.name: two folders; a benchmark: runs/NAME."""
    monkeypatch.chdir(tmp_path)
    for d in ("a", "b"):
        (tmp_path / d).mkdir()
        (tmp_path / d / "shift.toml").write_text(SHIFT)
        assert _run(capsys, "run", f"{d}/shift.toml", "--quiet")[0] == 0
    folders = sorted(p.name for p in (tmp_path / "runs").iterdir())
    assert len(folders) == 2 and all(f.startswith("shift-") and len(f) == len("shift-") + 8 for f in folders)
    sources = {_json(tmp_path / "runs" / f / "summary.json")["source"] for f in folders}
    assert sources == {"a/shift.toml", "b/shift.toml"}


def test_version(tmp_path) -> None:
    proc = subprocess.run(_cli() + ["--version"], capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert proc.returncode == 0 and proc.stdout == f"ctmrpim {__version__}\n"


def test_progress_in_a_log_is_plain_lines(tmp_path, capsys, monkeypatch) -> None:
    """stderr not a terminal, no delay: a line per phase of the run, newline-terminated, no carriage return;
    --quiet prints nothing."""
    monkeypatch.setattr(progress, "DELAY", 0.0)
    code, _, stderr = _run(capsys, "run", *LINEAR, "--out", str(tmp_path / "out"))
    assert code == 0 and "\r" not in stderr and "\x1b" not in stderr
    lines = stderr.splitlines()
    assert lines[0] == "ctmrpim: cantilever (linear, ctm-rpim, 17 x 5 nodes)"
    text = "\n".join(lines)
    for phase in ("boundary", "integration points", "shape functions", "assembly", "solve", "postprocessing",
                  "output"):
        assert f"{phase} " in text, phase
    assert all(line.startswith("ctmrpim: [") for line in lines[1:])
    assert _run(capsys, "run", *LINEAR, "--out", str(tmp_path / "out"), "--quiet")[2] == ""


def test_progress_on_a_terminal_is_one_live_line() -> None:
    """A live reporter rewrites one line (carriage return, erase) and erases it at the end; statuses of a
    stepping loop replace each other; a kept line is written in full."""
    stream = io.StringIO()
    reporter = progress.Progress(stream, live=True, title="demo", delay=0.0)
    with progress.reporting(reporter):
        timer = Timer()
        timer.lap("boundary", nodes=10)
        progress.current().status("step 50")
        progress.current().line("  a level")
    text = stream.getvalue()
    assert "\r\x1b[K" in text and "boundary 0.00 s (10 nodes) | integration points..." in text
    assert "step 50" in text and "  a level\n" in text and text.endswith("\r\x1b[K")
    assert progress.current() is progress.SILENT


def test_progress_in_a_log_waits_then_sums_a_loops_laps() -> None:
    """Nothing before the delay; the laps until then in one line, a loop's laps summed into one entry; the
    laps of a loop that reports a status are left out, and a status comes at most once per interval."""
    stream = io.StringIO()
    with progress.reporting(progress.Progress(stream, live=False, title="demo", delay=3600.0)):
        Timer().lap("boundary")
    assert stream.getvalue() == ""             # a quick run stays silent
    stream = io.StringIO()
    with progress.reporting(progress.Progress(stream, live=False, title="demo", delay=0.2, log_interval=0.0)):
        timer = Timer()
        timer.lap("boundary")
        for _ in range(100):
            timer.lap("forces")
        time.sleep(0.25)
        timer.lap("assembly")
        progress.current().status("step 1")
        for _ in range(100):
            timer.lap("material")              # laps of a loop that reports itself: not shown
        progress.current().status("")
        timer.lap("postprocess")
    lines = stream.getvalue().splitlines()
    assert len(lines) == 4 and lines[0] == "ctmrpim: demo", lines
    assert re.search(r"\] boundary \d\.\d\d s, forces \d\.\d\d s in 100 laps, assembly 0\.\d\d s$", lines[1]), lines
    assert lines[2].endswith("] step 1") and re.search(r"\] postprocessing \d\.\d\d s$", lines[3])
    stream = io.StringIO()
    with progress.reporting(progress.Progress(stream, live=False, delay=0.0, log_interval=3600.0)):
        Timer().lap("boundary")
        progress.current().status("step 1")    # within the interval after the last line: not written
    assert stream.getvalue().splitlines() == ["ctmrpim: [    0.0 s] boundary 0.00 s"]


def test_a_refused_resume_leaves_the_folder_as_it_was(tmp_path, capsys) -> None:
    """--resume with another setting: refused (exit 2), and the finished run it would have continued is
    still whole, its status record included."""
    out = tmp_path / "out"
    sets = ["--set", "nodes.grid=[16,9]", "--set", "explicit.duration=0.02", "--set", "explicit.checkpoint_every=20"]
    assert _run(capsys, "run", "column-collapse", *sets, "--out", str(out), "--quiet")[0] == 0
    before = {p.relative_to(out): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}
    code, _, stderr = _run(capsys, "run", "column-collapse", *sets, "--set", "material.phi=25", "--out", str(out),
                           "--resume")
    assert code == 2 and "belongs to another problem" in stderr
    after = {p.relative_to(out): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}
    assert after == before and _json(out / "status.json")["state"] == "ok"
