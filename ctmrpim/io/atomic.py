"""Atomic writes: a file appears under its final name only once it is complete.

Written to a temporary name in the same folder, then renamed, so an interrupted run never leaves a file
that looks finished. The temporary name is hidden, ``.NAME.XXXXXXXX.tmp``; a write that fails removes it,
and one that was killed leaves it behind for the next run in the folder to remove (:func:`leftovers`).
"""
from __future__ import annotations

import os
import re
import tempfile
from collections.abc import Callable, Iterable
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
