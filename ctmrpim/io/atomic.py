"""Atomic writes: a file appears under its final name only once it is complete.

Written to a temporary name in the same folder, then renamed, so an interrupted run never leaves a file
that looks finished. The temporary name is hidden, ``.NAME.XXXXXXXX.tmp``; a write that fails removes it,
and one that was killed leaves it behind for the next run in the folder to remove (:func:`leftovers`).
"""
from __future__ import annotations

import contextlib
import os
import re
import signal
import tempfile
import threading
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

#: the temporary name of a file NAME being written: mkstemp's random part has no dot
TEMPORARY = re.compile(r"\.(?P<name>.+)\.[^.]+\.tmp")


def atomic_write(path: Path, write: Callable[[Path], object]) -> None:
    """Call ``write(tmp_path)`` and rename the file to ``path`` once it succeeded."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; the final file gets the usual permissions
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` atomically."""
    atomic_write(path, lambda p: p.write_text(text))


def leftovers(folder: Path, names: Iterable[str] | None = None) -> list[Path]:
    """The temporary files in ``folder`` that writes of ``names`` (default: of any name) left behind."""
    folder = Path(folder)
    wanted = None if names is None else set(names)
    found = []
    for p in sorted(folder.iterdir()):
        m = TEMPORARY.fullmatch(p.name)
        if m and p.is_file() and (wanted is None or m["name"] in wanted):
            found.append(p)
    return found


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """SIGINT and SIGTERM held back until the block is done, then handled as they would have been: for a write that
    must not be cut in the middle. numpy's savez closes its archive in a ``finally`` that fails on an entry still
    open, so Ctrl-C inside it ended a run with a ValueError (exit 1) instead of the interruption (exit 130), and
    on older numpy left a ZipFile whose finaliser printed a traceback. Only in the main thread (the only one
    where Python runs signal handlers); a signal whose handler was not set from Python is left alone."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[tuple[int, object]] = []
    previous = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    previous = {s: h for s, h in previous.items() if h is not None}
    for s in previous:
        signal.signal(s, lambda signum, frame: caught.append((signum, frame)))
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
        if caught:
            signum, frame = caught[0]
            handler = previous[signum]
            if callable(handler):
                handler(signum, frame)
            elif handler == signal.SIG_DFL:
                signal.raise_signal(signum)
