"""What a running solve is doing, on stderr: the one progress reporter of every analysis.

The command line installs a :class:`Progress` for the length of ``ctmrpim run`` (:func:`reporting`); solvers
never take it as an argument but reach it through :func:`current`, which is :data:`SILENT` unless the
command line installed one, so the Python API, the studies and the tests print nothing. Three things feed it:

- every :meth:`ctmrpim.timing.Timer.lap` (boundary, integration points, shape functions, assembly, solve,
  postprocessing; the command line adds output): :meth:`Progress.phase`;
- loops that go on for long (Newton's increments and iterations, dynamic relaxation's steps, the explicit
  solver's steps): :meth:`Progress.status`, a line saying where the loop is, which replaces the previous one
  (an empty one when the loop is over); a loop run within a larger one (a strength-reduction level's Newton
  iterations) is labelled by :meth:`Progress.stage`;
- results worth keeping on screen (a strength-reduction level): :meth:`Progress.line`.

On a terminal it keeps one live line, rewritten in place (a carriage return and erase-line) and ticking
every half second so that a long phase is seen to be running, and erased at the end. When stderr is not a
terminal (a log file, a pipe) it writes plain newline-terminated lines instead, never a carriage return:
nothing for a run that ends within :data:`DELAY` seconds (so quick runs and scripts stay quiet), then the
phases finished so far in one line and a line per phase after that; a status, or a phase that is still
running, gets a line once nothing was written for :data:`LOG_INTERVAL` seconds. The phase shown as running
is the one that follows the last finished phase in the static solvers (:data:`NEXT`).
"""
from __future__ import annotations

import contextlib
import shutil
import sys
import threading
import time
from typing import Iterator, TextIO

#: seconds after which a log (stderr not a terminal) starts getting lines; quicker runs print nothing
DELAY = 5.0
#: seconds after which a terminal shows the live line (a quicker run never flickers one)
LIVE_DELAY = 0.5
#: at most one status line per this many seconds in a log
LOG_INTERVAL = 10.0
#: the live line is redrawn at most this often (seconds), and at least every TICK while a phase runs
REDRAW = 0.1
TICK = 0.5

#: how a phase booked by a Timer lap reads on screen (other names: underscores become spaces)
NAMES = {"integration": "integration points", "shape_functions": "shape functions",
         "postprocess": "postprocessing", "set_up": "set-up", "transfer": "state transfer",
         "time_step": "time step"}
#: what usually runs after a phase of the static solvers, shown on a terminal while it runs
NEXT = {"boundary": "integration points", "integration": "shape functions", "shape_functions": "assembly",
        "mesh": "assembly", "assembly": "solve", "solve": "postprocessing", "postprocess": "output"}


def phase_name(name: str) -> str:
    """The readable name of a Timer phase (``"shape_functions"`` -> ``"shape functions"``)."""
    return NAMES.get(name, name.replace("_", " "))


class Silent:
    """The reporter when nobody asked for progress: every call does nothing (cheap enough for every step)."""

    def phase(self, name: str, seconds: float, **counts: int) -> None:
        """Ignore a finished phase."""

    def status(self, text: str) -> None:
        """Ignore a status."""

    def line(self, text: str) -> None:
        """Ignore a line."""

    def stage(self, label: str) -> contextlib.AbstractContextManager[None]:
        """Nothing to label: a context that does nothing."""
        return contextlib.nullcontext()

    def close(self) -> None:
        """Nothing to close."""


class Progress(Silent):
    """Progress of one command on ``stream``: a live line on a terminal, plain lines in a log.

    ``live`` forces one behaviour (default: whether ``stream`` is a terminal); ``title`` names the run
    (problem, analysis, method, nodes) in the first log line, ``name`` (default ``title``) at the start of
    the live line, where the width is short; ``delay`` (default :data:`DELAY`, :data:`LIVE_DELAY` on a
    terminal) is how long a run goes before anything is shown; ``log_interval`` (default
    :data:`LOG_INTERVAL`) the least time between a log's status lines."""

    def __init__(self, stream: TextIO | None = None, *, live: bool | None = None, title: str = "", name: str = "",
                 delay: float | None = None, log_interval: float | None = None) -> None:
        self.stream = sys.stderr if stream is None else stream
        if live is None:
            isatty = getattr(self.stream, "isatty", None)
            live = bool(isatty and isatty())
        self.live, self.title, self.name = live, title, name or title
        self.delay = (LIVE_DELAY if live else DELAY) if delay is None else delay
        self.log_interval = LOG_INTERVAL if log_interval is None else log_interval
        self.label = ""                          # the stage the statuses belong to (see stage)
        self.t0 = time.perf_counter()
        self.last: tuple[str, float, dict[str, int]] | None = None    # the last phase finished
        self.pending: dict[str, list] = {}      # log: phases finished since the last line: [seconds, laps, counts]
        self.state = ""                          # the last status
        self.shown = False                       # log: a line was written; terminal: the live line is up
        self.last_line = -float("inf")           # log: when a line was last written (elapsed seconds)
        self.last_draw = -float("inf")           # terminal: when the live line was last drawn
        self.lock = threading.RLock()
        self.done = threading.Event()
        # a phase can run for many seconds without a lap (one sparse factorisation): a clock thread keeps
        # the live line ticking, or writes a log line saying what is still running
        self.ticker = threading.Thread(target=self._tick, name="ctmrpim-progress", daemon=True)
        self.ticker.start()

    # -- what the solvers report ----------------------------------------------------------------------
    def elapsed(self) -> float:
        """Seconds since the reporter started."""
        return time.perf_counter() - self.t0

    def phase(self, name: str, seconds: float, **counts: int) -> None:
        """A phase of the run ended after ``seconds`` (a Timer lap), with what it counted (nodes, points)."""
        self.last = (name, seconds, counts)
        if self.live:
            self._draw()
            return
        if self.state:          # a stepping loop reports itself by status: its laps (every step) would flood a log
            return
        with self.lock:
            booked = self.pending.setdefault(name, [0.0, 0, {}])    # a loop's laps add up to one entry
            booked[0] += seconds
            booked[1] += 1
            booked[2].update(counts)
            if self.elapsed() >= self.delay:
                self._write_pending()

    def status(self, text: str) -> None:
        """Where a long loop is now (replaces the previous status); ``""`` when the loop is over, so that the
        phases after it are shown again."""
        self.state = f"{self.label}: {text}" if self.label and text else text
        if not text:
            return
        if self.live:
            self._draw()
            return
        now = self.elapsed()
        if now >= self.delay and now - self.last_line >= self.log_interval:
            self._write_pending(self.state)

    def line(self, text: str) -> None:
        """A line to keep (a strength-reduction level), written at once whatever the delay."""
        with self.lock:
            self._clear()
            if not self.live and not self.shown and self.title:   # a log names the run before its first line
                self.stream.write(f"ctmrpim: {self.title}\n")
                self.shown = True
            self.stream.write(text + "\n")
            self.stream.flush()
        if self.live:
            self._draw(force=True)

    @contextlib.contextmanager
    def stage(self, label: str) -> Iterator[None]:
        """Label every status within the ``with`` block with ``label`` (``"SRF 1.3500"``: the loops that
        report do not know the level they serve)."""
        previous, self.label = self.label, label
        try:
            yield
        finally:
            self.label = previous

    def close(self) -> None:
        """The run is over: stop the clock, erase the live line; a log gets the phases it has not seen yet
        (only if it got a line before, so that a quick run stays silent)."""
        self.done.set()
        self.ticker.join()
        with self.lock:
            self._clear()
            self.stream.flush()
        if not self.live and self.shown and self.pending:
            self._write_pending()

    # -- drawing ----------------------------------------------------------------------------------------
    def _tick(self) -> None:
        while not self.done.wait(TICK):
            if self.live:
                self._draw(force=True)
                continue
            now = self.elapsed()
            if now >= self.delay and now - self.last_line >= self.log_interval:
                with self.lock:
                    self._write_pending(self._running() + ("" if self.state else " (running)"))

    def _running(self) -> str:
        """What is running now: the status, else the phase that follows the last one finished."""
        if self.state:
            return self.state
        if self.last is None:
            return "setting up..."
        name = self.last[0]
        return f"{NEXT[name]}..." if name in NEXT else f"after {phase_name(name)}..."

    def _live_text(self) -> str:
        parts = [f"[{self.elapsed():6.1f} s]"] + ([self.name + ":"] if self.name else [])
        if not self.state and self.last is not None:
            parts.append(_phase_text(*self.last) + " |")
        parts.append(self._running())
        return " ".join(parts)

    def _draw(self, force: bool = False) -> None:
        now = self.elapsed()
        if now < self.delay or self.done.is_set() or (not force and now - self.last_draw < REDRAW):
            return
        width = shutil.get_terminal_size((100, 24)).columns - 1
        with self.lock:
            self.stream.write("\r\x1b[K" + self._live_text()[:width])
            self.stream.flush()
            self.shown, self.last_draw = True, now

    def _clear(self) -> None:
        """Erase the live line (call with the lock held)."""
        if self.live and self.shown:
            self.stream.write("\r\x1b[K")
            self.shown = False

    def _write(self, text: str) -> None:
        """Write a log line (the run's title before the first)."""
        with self.lock:
            if not self.shown and self.title:
                text = f"{self.title}\nctmrpim: {text}"
            self.stream.write(f"ctmrpim: {text}\n")
            self.stream.flush()
            self.shown, self.last_line = True, self.elapsed()

    def _write_pending(self, running: str = "") -> None:
        """Write the phases finished since the last line in one line, and what is ``running`` now if given."""
        with self.lock:
            if self.pending or running:
                done = ", ".join(_phase_text(name, seconds, counts) + (f" in {laps} laps" if laps > 1 else "")
                                 for name, (seconds, laps, counts) in self.pending.items())
                self._write(f"[{self.elapsed():7.1f} s] " + " | ".join(p for p in (done, running) if p))
                self.pending = {}


def _phase_text(name: str, seconds: float, counts: dict[str, int]) -> str:
    text = f"{phase_name(name)} {seconds:.2f} s"
    if counts:
        text += " (" + ", ".join(f"{v} {k.replace('_', ' ')}" for k, v in counts.items()) + ")"
    return text


#: the reporter of code that runs outside ``ctmrpim run``
SILENT = Silent()
_current: Silent = SILENT


def current() -> Silent:
    """The reporter in force: the command line's :class:`Progress` during ``ctmrpim run``, else :data:`SILENT`."""
    return _current


@contextlib.contextmanager
def reporting(reporter: Silent) -> Iterator[Silent]:
    """Install ``reporter`` as :func:`current` for the ``with`` block, and close it at the end."""
    global _current
    previous, _current = _current, reporter
    try:
        yield reporter
    finally:
        _current = previous
        reporter.close()
