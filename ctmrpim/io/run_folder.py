"""A run's output folder: one run per folder, with a status record that says what state it is in.

What ``ctmrpim run`` writes into its folder:

- ``status.json``, first: ``state`` "running", when it started, the command, the version, the process; at
  the end the state becomes "ok", "not converged", "interrupted" (Ctrl-C or SIGTERM) or "failed" with the
  time it ended, the exit status and the reason. A folder whose status still says "running" belongs to a
  run that is going on, or one that was killed outright (SIGKILL).
- ``result.vtu``, the series (``result.pvd`` + ``series/step_*.vtu``), an explicit run's ``checkpoint.npz``,
  and ``summary.json`` last (:func:`write_outputs`, all or none). A run that did not converge writes a
  ``summary.json`` with ``status`` "not converged", the reason and the history up to there, and no result.

When a run starts, what an earlier run left in the folder is removed first (:func:`remove_outputs`), so that
a folder never mixes two runs: its result, series, summary, status, checkpoint (kept by ``--resume``, which
continues it) and any hidden ``.NAME.*.tmp`` left by a write that was killed. Only files under those names
are ever removed: a file ctmrpim does not write is left where it is, and a folder that holds one of those
names without a record that ctmrpim wrote it (its ``status.json``, ``summary.json`` or checkpoint) is
refused with one line rather than emptied (``--out .`` in a folder with someone's ``summary.json``).

The default folder (:func:`default_folder`) is ``runs/NAME`` for a benchmark and ``runs/STEM-HASH`` for a
problem file (its file name without ``.toml`` and 8 hex digits of the SHA-256 of its absolute path), so
that two problem files never share a folder, even with the same ``problem.name`` or the same file name.
"""
from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import socket
import time
from datetime import datetime
from pathlib import Path
from typing import Any

from ctmrpim.errors import ConvergenceError, ProblemError
from ctmrpim.io.atomic import TEMPORARY, atomic_write_text, leftovers
from ctmrpim.io.checkpoint import NAME as CHECKPOINT
from ctmrpim.io.summary import json_text, write_partial_summary, write_summary
from ctmrpim.io.vtu import write_series, write_vtu
from ctmrpim.problem.case import Case
from ctmrpim.result import Result
from ctmrpim.version import __version__

STATUS = "status.json"
SUMMARY = "summary.json"
SERIES = "series"
#: the files of a run, besides the series (``series/step_*.vtu``) and the status record
FILES = ("result.vtu", "result.pvd", SUMMARY, CHECKPOINT)
#: what a resumed run keeps of the run it continues (an explicit run's checkpoint and the series it wrote)
RESUMED = (CHECKPOINT, "result.pvd", SERIES)
STEP = re.compile(r"step_\d+\.vtu")
#: the program's name in its status records, which marks a folder as a ctmrpim run's
PROGRAM = "ctmrpim"


def default_folder(target: str, case: Case, benchmark: bool, suffix: str = "") -> Path:
    """``runs/NAME`` for the benchmark ``target``, ``runs/STEM-HASH`` for a problem file (its stem and the first
    8 hex digits of the SHA-256 of its resolved path); ``suffix`` (e.g. ``-fem-q1``) appended."""
    if benchmark:
        return Path("runs") / f"{target}{suffix}"
    path = Path(case.source).resolve()
    digest = hashlib.sha256(str(path).encode()).hexdigest()[:8]
    return Path("runs") / f"{path.stem}-{digest}{suffix}"


def run_files(folder: Path, resume: bool = False, status: bool = False) -> list[Path]:
    """The files in ``folder`` that a run writes (see the module), left out what ``resume`` keeps, and the
    status record only if ``status``."""
    folder = Path(folder)
    keep = RESUMED if resume else ()
    names = FILES + ((STATUS,) if status else ())
    found = [folder / n for n in names if n not in keep and (folder / n).is_file()]
    series = folder / SERIES
    if series.is_dir() and SERIES not in keep:
        found += sorted(p for p in series.iterdir() if STEP.fullmatch(p.name) and p.is_file())
    return found + temporaries(folder)


def temporaries(folder: Path) -> list[Path]:
    """The hidden temporary files (``.NAME.XXXXXXXX.tmp``) that writes of a run's files left in ``folder`` and
    its series: a write that was stopped before it could remove its own."""
    folder = Path(folder)
    series = folder / SERIES
    found = [p for p in leftovers(series) if STEP.fullmatch(TEMPORARY.fullmatch(p.name)["name"])] \
        if series.is_dir() else []
    return found + leftovers(folder, FILES + (STATUS,))


def remove_outputs(folder: Path, resume: bool = False) -> None:
    """Remove what a run wrote into ``folder`` (:func:`run_files`; ``resume`` keeps the checkpoint and the
    series), and ``series/`` once it is empty, but not the status record (the run that calls this writes its
    own). Nothing else is touched."""
    for p in run_files(folder, resume):
        p.unlink(missing_ok=True)
    series = Path(folder) / SERIES
    if series.is_dir() and not any(series.iterdir()):
        series.rmdir()


def _written_by_ctmrpim(folder: Path) -> bool:
    """Whether ``folder`` holds a record that ctmrpim wrote its run files: a status record of a ctmrpim run,
    a summary with its version, or a checkpoint with its metadata."""
    for name, is_ours in ((STATUS, lambda r: r.get("program") == PROGRAM), (SUMMARY, lambda r: "ctmrpim_version" in r)):
        try:
            record = json.loads((folder / name).read_text())
        except (OSError, ValueError):
            continue
        if isinstance(record, dict) and is_ours(record):
            return True
    try:
        import numpy as np
        with np.load(folder / CHECKPOINT) as data:
            return "meta" in data.files
    except (OSError, ValueError):
        return False


def _now() -> str:
    return datetime.now().astimezone().isoformat(timespec="seconds")


class RunFolder:
    """The output folder of one ``ctmrpim run``: :meth:`start` it, then end it with :meth:`write_result`,
    :meth:`not_converged`, :meth:`finish` (interrupted, failed) or :meth:`discard` (bad input: nothing
    written). ``command`` is the command line as typed, for the status record; ``notes`` (the warnings the run
    printed, a list that may grow while it runs) go into the summary's ``notes``."""

    def __init__(self, path: Path, *, command: str, source: str, method: str, resume: bool = False,
                 notes: list[str] | None = None) -> None:
        self.path = Path(path)
        self.command, self.source, self.method, self.resume = command, source, method, resume
        self.notes = notes if notes is not None else []
        self.created = False
        self.previous: str | None = None     # --resume: the status record of the run it continues
        self.status: dict[str, Any] = {}
        self.t0 = time.perf_counter()

    def start(self) -> None:
        """Check the folder, remove an earlier run's files, write the status record "running". A folder that
        cannot be written, or that holds files under a run's names that ctmrpim did not write, is a
        ProblemError (key ``--out``) and is left as it was. With ``resume`` nothing is removed here: the
        explicit solver removes what the resumed run replaces once it has accepted the checkpoint, so that a
        refused ``--resume`` leaves the folder as it found it."""
        out = self.path
        if out.exists() and not out.is_dir():
            raise ProblemError(f"cannot write the results to {str(out)!r} (it is a file, not a folder)", key="--out")
        if out.is_dir():
            ours = [p for p in run_files(out, status=True) if not p.name.startswith(".")]
            if ours and not _written_by_ctmrpim(out):
                names = ", ".join(str(p.relative_to(out)) for p in ours[:3]) + (", ..." if len(ours) > 3 else "")
                raise ProblemError(f"{str(out)!r} holds {names}, which no ctmrpim run there wrote (no status.json "
                                   "or summary.json of one): choose another --out, or remove them", key="--out")
        try:
            self.created = not out.exists()
            out.mkdir(parents=True, exist_ok=True)
            if self.resume:
                self.previous = (out / STATUS).read_text() if (out / STATUS).is_file() else None
            else:
                remove_outputs(out)
            self.status = {"program": PROGRAM, "version": __version__, "state": "running", "started": _now(),
                           "command": self.command, "cwd": os.getcwd(), "source": self.source, "method": self.method,
                           "resume": self.resume, "pid": os.getpid(), "host": socket.gethostname()}
            atomic_write_text(out / STATUS, json_text(self.status))
        except OSError as exc:  # a read-only folder, a path through a file
            if self.created:
                shutil.rmtree(out, ignore_errors=True)
            raise ProblemError(f"cannot write the results to {str(out)!r} ({exc.strerror or exc})",
                               key="--out") from None

    def finish(self, state: str, exit_status: int, error: str | None = None,
               outputs: list[Path] | None = None) -> None:
        """Set the status record's ``state`` ("ok", "not converged", "interrupted", "failed") with the end time,
        seconds, exit status, the reason and the files written. A temporary file that a write stopped by the
        interrupt left (the signal came between creating it and the clean-up that guards it) is removed."""
        for p in temporaries(self.path):
            p.unlink(missing_ok=True)
        self.status.update(state=state, finished=_now(), seconds=round(time.perf_counter() - self.t0, 3),
                           exit_status=exit_status)
        if error is not None:
            self.status["error"] = error
        if outputs is not None:   # the series as a count: a long explicit run writes hundreds of states
            names = [p.relative_to(self.path).as_posix() for p in outputs]
            self.status["outputs"] = [n for n in names if not n.startswith(f"{SERIES}/")]
            self.status["series_files"] = len(names) - len(self.status["outputs"])
        atomic_write_text(self.path / STATUS, json_text(self.status))

    def write_result(self, result: Result, case: Case) -> list[Path]:
        """Write the run's outputs (:func:`write_outputs`: result, series, summary last), then the status "ok";
        the paths written."""
        paths = write_outputs(result, case, self.path, self.notes)
        # what the folder holds, not only what was written now: an explicit run wrote its series as it went
        self.finish("ok", 0, outputs=[p for p in run_files(self.path) if not p.name.startswith(".")])
        return paths

    def not_converged(self, error: ConvergenceError, case: Case) -> Path:
        """A solve that did not converge: ``summary.json`` with the reason and the history up to there, then
        the status "not converged" (exit status 3); what the run wrote as it went (an explicit run's series
        and checkpoint) stays. The summary's path."""
        path = write_partial_summary(self.path, source=case.source, method=self.method, parameters=case.resolved,
                                     defaults=case.defaults, status="not converged", error=error.message,
                                     history=error.history, seconds=time.perf_counter() - self.t0,
                                     notes=self.notes)
        kept = [p for p in run_files(self.path) if not p.name.startswith(".")]
        self.finish("not converged", 3, error=error.message, outputs=kept)
        return path

    def discard(self) -> None:
        """Bad input found while solving: remove what this run wrote (and the folder, if it made it), so that
        a refused run leaves nothing behind; a refused ``--resume`` puts the status record back as it was."""
        if self.created:
            shutil.rmtree(self.path, ignore_errors=True)
        elif self.resume:
            if self.previous is None:
                (self.path / STATUS).unlink(missing_ok=True)
            else:
                atomic_write_text(self.path / STATUS, self.previous)
        else:
            remove_outputs(self.path)
            (self.path / STATUS).unlink(missing_ok=True)


def write_outputs(result: Result, case: Case, out: Path, notes: list[str] | None = None) -> list[Path]:
    """result.vtu, the increment series (result.pvd + series/*.vtu) where there is one, and
    summary.json last (with ``notes`` on the run); all or none (a folder this call created is removed again
    if a write fails or the run is interrupted, so a failed run never leaves a half-written result behind)."""
    created = not out.exists()
    paths: list[Path] = []
    try:
        paths.append(write_vtu(result, out))
        for p in write_series(result, out):
            paths.append(p)
        paths.append(write_summary(result, out, case.source, notes or ()))
    except BaseException as exc:
        for p in paths:
            p.unlink(missing_ok=True)
        if created:
            shutil.rmtree(out, ignore_errors=True)
        if isinstance(exc, OSError):  # e.g. --out names an existing file, or a read-only folder
            raise ProblemError(f"cannot write the results to {str(out)!r} ({exc.strerror or exc})",
                               key="--out") from None
        raise
    return paths
