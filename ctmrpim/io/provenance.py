"""Which code computed a result: the package version and a hash of the sources that compute results.

Cached sweep cases and explicit checkpoints are keyed by it, so changed code never serves a stale
result. Only code that computes results counts: the command line (:mod:`ctmrpim.cli`) presents
results and is left out, and the application above the package (sweeps, studies, report, in
``studies/``) lies outside it, so editing the report's prose or the CLI's help invalidates nothing.
Python sources are hashed without their docstrings, comments and blank lines
(:func:`normalised_source`): an edit that cannot change a number invalidates nothing either.
"""
from __future__ import annotations

import ast
import hashlib
import io
import tokenize
from functools import cache
from pathlib import Path

from ctmrpim.version import __version__

#: files of this package that present results, or hash the sources, but never compute a result
PRESENTATION = ("cli.py", "io/provenance.py")
PACKAGE = Path(__file__).resolve().parents[1]


def hashed_files(package: Path, exclude: tuple[str, ...] = ()) -> list[Path]:
    """The ``.py`` files of ``package`` whose contents a source hash covers, in a fixed order."""
    package = Path(package)
    return [f for f in sorted(package.rglob("*.py")) if f.relative_to(package).as_posix() not in exclude]


def _docstring_lines(tree: ast.AST, lines: list[str]) -> set[int]:
    """Indices of the lines that hold nothing but a module's, class's or function's docstring."""
    out: set[int] = set()
    for node in ast.walk(tree):
        if not isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) or not node.body:
            continue
        first = node.body[0]
        if not (isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant)
                and isinstance(first.value.value, str)):
            continue
        start, end = first.lineno - 1, first.end_lineno - 1
        # a docstring that shares a line with code (``def f(): "doc"; return 1``) is kept whole
        if lines[start][:first.col_offset].strip() or lines[end][first.end_col_offset:].strip(" \t;"):
            continue
        out.update(range(start, end + 1))
    return out


def normalised_source(text: str) -> str:
    """``text`` (Python source) without docstrings, comments, trailing blanks and blank lines: what a hash of
    the code that computes results should see. Plain text, so it reads the same under every Python version;
    a file that does not parse is returned unchanged (its hash then moves with every edit)."""
    try:
        tree = ast.parse(text)
        comments = {tok.start: tok.start[1] for tok in tokenize.generate_tokens(io.StringIO(text).readline)
                    if tok.type == tokenize.COMMENT}
    except (SyntaxError, tokenize.TokenError, ValueError):
        return text
    lines = text.splitlines()
    for (row, _), col in comments.items():
        lines[row - 1] = lines[row - 1][:col]
    dropped = _docstring_lines(tree, text.splitlines())
    kept = (ln.rstrip() for i, ln in enumerate(lines) if i not in dropped)
    return "\n".join(ln for ln in kept if ln) + "\n"


def file_digest(path: Path) -> str:
    """sha256 of a source file as a hash of results sees it: a ``.py`` file's :func:`normalised_source`, any
    other file's bytes."""
    path = Path(path)
    data = normalised_source(path.read_text()).encode() if path.suffix == ".py" else path.read_bytes()
    return hashlib.sha256(data).hexdigest()


def source_hash(package: Path, exclude: tuple[str, ...] = ()) -> str:
    """sha256 over the relative paths and normalised contents (:func:`file_digest`) of :func:`hashed_files`
    (inputs such as benchmark files are part of a case's resolved input, not of the code)."""
    package = Path(package)
    digest = hashlib.sha256()
    for f in hashed_files(package, exclude):
        digest.update(f.relative_to(package.parent).as_posix().encode())
        digest.update(file_digest(f).encode())
    return digest.hexdigest()


@cache
def code_version() -> str:
    """``VERSION+HASH`` of this package's result-computing sources."""
    return f"{__version__}+{source_hash(PACKAGE, PRESENTATION)[:16]}"
