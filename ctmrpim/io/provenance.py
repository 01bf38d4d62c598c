"""Which code computed a result: the package version and a hash of the sources that compute results.

Cached sweep cases and explicit checkpoints are keyed by it, so changed code never serves a stale
result. Only code that computes results counts: the command line (:mod:`ctmrpim.cli`) presents
results and is left out, and the application above the package (sweeps, studies, report, in
``studies/``) lies outside it, so editing the report's prose or the CLI's help invalidates nothing.
"""
from __future__ import annotations

import hashlib
from functools import cache
from pathlib import Path

from ctmrpim.version import __version__

#: files of this package that present results but never compute them
PRESENTATION = ("cli.py",)
PACKAGE = Path(__file__).resolve().parents[1]


def hashed_files(package: Path, exclude: tuple[str, ...] = ()) -> list[Path]:
    """The ``.py`` files of ``package`` whose contents a source hash covers, in a fixed order."""
    package = Path(package)
    return [f for f in sorted(package.rglob("*.py")) if f.relative_to(package).as_posix() not in exclude]


def source_hash(package: Path, exclude: tuple[str, ...] = ()) -> str:
    """sha256 over the relative paths and contents of :func:`hashed_files` (inputs such as benchmark
    files are part of a case's resolved input, not of the code)."""
    package = Path(package)
    digest = hashlib.sha256()
    for f in hashed_files(package, exclude):
        digest.update(f.relative_to(package.parent).as_posix().encode())
        digest.update(f.read_bytes())
    return digest.hexdigest()


@cache
def code_version() -> str:
    """``VERSION+HASH`` of this package's result-computing sources."""
    return f"{__version__}+{source_hash(PACKAGE, PRESENTATION)[:16]}"
