"""Provenance of the committed full-mode results (``reports/full/``): which code made each table and figure, and
whether the current code would still make it.

Every full-mode run of a study (:func:`studies.base.run_study` with ``quick=False``) writes beside its
``NAME.csv`` and ``NAME.png`` a sidecar ``NAME.provenance.json``: the package version, the git commit of the
working tree and whether its numerics differed from that commit, the sha256 of the two files it describes, and
the sha256 of every *numerics source* the study depends on (:func:`numerics_files`): the ``ctmrpim`` package
(its command line aside, as for the sweep cache's key, :mod:`ctmrpim.io.provenance`), its benchmark files and
data, the ``reference_fem`` package with its golden results, and the study's own module with the study modules
it imports (the sweep executor, the command line and the report aside: they compute nothing).

:func:`status` compares a sidecar with the current tree. A result is *current* when every numerics source hashes
as it did, *stale* when one changed, was added or removed (the report names them and does not quote the result
silently), *modified* when the table or figure no longer hashes as stamped (rewritten without a new stamp), and
*unstamped* without a sidecar. ``python -m studies.provenance reports/full`` prints every result's state;
``--stamp NAME --commit SHA`` stamps a result made before stamping existed with the sources of the commit that
committed it (what the run can at best be traced to).

A source is hashed as the sweep cache hashes it (:func:`ctmrpim.io.provenance.file_digest`: Python without
docstrings, comments and blank lines). A study module is hashed without its ``figure`` function, which draws the
table and computes nothing in it (after an edit there, ``python -m studies.redraw NAME`` draws the figure again
from the committed table and records the new figure's hash, and the result stays current), and without its ``specs`` function and
what only that uses: the full run's case list itself is hashed instead (:func:`full_cases`), so a change of the
quick mode's cases leaves a full-mode result current while any change of a full case makes it stale.
"""
from __future__ import annotations

import argparse
import ast
import datetime as _dt
import hashlib
import json
import subprocess
from dataclasses import dataclass, field
from pathlib import Path

from ctmrpim.io.provenance import PRESENTATION, file_digest, normalised_source
from ctmrpim.version import __version__

ROOT = Path(__file__).resolve().parents[1]
SUFFIX = ".provenance.json"
#: the files of a study's result that a sidecar describes
OUTPUTS = (".csv", ".png")
#: modules of ``studies`` that compute nothing (executor, command line, report): not numerics sources
NOT_NUMERICS = ("studies.sweep", "studies.cli", "studies.commands", "studies.report", "studies.provenance",
                "studies.redraw")
#: top-level functions of a study module that draw its table and compute nothing in it
DRAWING = ("figure",)
#: top-level functions of a study module that list its cases (hashed as the full run's case list instead)
CASE_LISTING = ("specs",)


def _package_files(root: Path, package: str) -> list[str]:
    """The files of ``package`` (relative to ``root``) that its results depend on: every file but caches and,
    for ``ctmrpim``, the command line."""
    base = root / package
    out = []
    for f in sorted(base.rglob("*")):
        rel = f.relative_to(base).as_posix()
        if not f.is_file() or "__pycache__" in f.parts or f.suffix in (".pyc", ".nbc", ".nbi"):
            continue
        if package == "ctmrpim" and rel in PRESENTATION:
            continue
        out.append(f.relative_to(root).as_posix())
    return out


def _study_modules(root: Path, name: str) -> list[str]:
    """``studies/NAME.py`` and the ``studies`` modules it imports, transitively (statically, from the source without
    its case listing and drawing, :func:`_without_cases_and_drawing`)."""
    seen: set[str] = set()
    todo = [f"studies.{name}"]
    while todo:
        mod = todo.pop()
        if mod in seen or mod.startswith(NOT_NUMERICS):
            continue
        path = root / (mod.replace(".", "/") + ".py")
        if not path.is_file():
            continue
        seen.add(mod)
        tree = ast.parse(_without_cases_and_drawing(path.read_text()))   # what drawing imports computes nothing
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:   # relative: from .x import y, from . import x
                    base = ".".join(mod.split(".")[:-node.level] + ([base] if base else []))
                targets = [base] + [f"{base}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                continue
            todo += [t for t in targets if t.startswith("studies.")]
    return sorted(m.replace(".", "/") + ".py" for m in seen)


def numerics_files(study: str, root: Path = ROOT) -> list[str]:
    """The numerics sources of ``study`` (paths relative to the repository root), in a fixed order."""
    return _package_files(root, "ctmrpim") + _package_files(root, "reference_fem") + _study_modules(root, study)


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _defined(node: ast.stmt) -> set[str]:
    """The module-level names a top-level statement defines (a function, a class, an assignment's targets)."""
    if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
        return {node.name}
    targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(
        node, (ast.AnnAssign, ast.AugAssign)) else []
    return {n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)}


def _used(nodes: list[ast.stmt]) -> set[str]:
    """The names ``nodes`` read."""
    return {n.id for node in nodes for n in ast.walk(node) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}


def _without_cases_and_drawing(text: str) -> str:
    """A study module's source without the code that only lists its cases or draws its table: the
    :data:`CASE_LISTING` and :data:`DRAWING` functions, and the top-level definitions (helpers, constants such as
    quick and full grids) that only they use. What the full run computes from those is hashed as its case list
    (:func:`full_cases`)."""
    body = ast.parse(text).body
    gone = [n for n in body if isinstance(n, ast.FunctionDef) and n.name in DRAWING + CASE_LISTING]
    while True:
        kept = [n for n in body if n not in gone]
        used_by_kept, used_by_gone = _used(kept), _used(gone)
        more = [n for n in kept if _defined(n) and not _defined(n) & used_by_kept and _defined(n) & used_by_gone]
        if not more:
            break
        gone += more
    lines = text.splitlines()
    for node in gone:
        start = min([node.lineno] + [d.lineno for d in getattr(node, "decorator_list", [])]) - 1
        lines[start:node.end_lineno] = [""] * (node.end_lineno - start)
    return "\n".join(lines) + "\n"


def _digest(path: Path, study_module: bool) -> str:
    """sha256 (16 hex digits) of one numerics source: :func:`file_digest`, a study module without its case
    listing and drawing. Normalised once per content in a process (the report asks for every study's state
    several times, and every study shares the package's two hundred sources: parsing them is the cost)."""
    data = path.read_bytes()
    key = (_sha(data), path.suffix, study_module)
    if key not in _DIGESTS:
        if study_module:
            _DIGESTS[key] = _sha(normalised_source(_without_cases_and_drawing(data.decode())).encode())[:16]
        else:
            _DIGESTS[key] = file_digest(path)[:16]
    return _DIGESTS[key]


#: :func:`_digest`'s results by (sha256 of the raw file, suffix, study module)
_DIGESTS: dict[tuple[str, str, bool], str] = {}


def _listed(specs: list, root: str) -> str:
    """sha256 (16 hex digits) of a case list: each case's benchmark, overrides, method, element and coordinates,
    with paths inside the tree ``root`` made relative to it (the same tree hashes alike wherever it lies)."""
    def rel(text: str) -> str:
        return text.replace(root.rstrip("/") + "/", "")
    rows = [[rel(s.target), [rel(o) for o in s.overrides], s.solver, s.element, [list(kv) for kv in s.labels]]
            for s in specs]
    return hashlib.sha256(json.dumps(rows, sort_keys=True, default=str).encode()).hexdigest()[:16]


#: run by another tree's interpreter: that tree's study lists its full cases, this module's rule hashes them
_CASES_SCRIPT = """
import importlib, sys
module = importlib.import_module("studies." + sys.argv[1])
if hasattr(module, "specs"):
    print(listed(module.specs(False), __import__("os").getcwd()))
"""


def full_cases(study: str, root: Path = ROOT) -> str | None:
    """sha256 (16 hex digits) of the full run's case list of ``study`` (each case's benchmark, overrides, method,
    element and study coordinates, in order) as the tree at ``root`` makes it; None for a module without
    ``specs``, "unavailable" where that tree cannot list them. The benchmark files and the code that resolves and
    solves the cases are hashed as files."""
    if Path(root).resolve() != ROOT:   # another tree's code: listed by an interpreter that imports it
        import inspect
        import os
        import sys
        script = f"import hashlib, json\n{inspect.getsource(_listed)}\nlisted = _listed\n{_CASES_SCRIPT}"
        out = subprocess.run([sys.executable, "-c", script, study], cwd=root, capture_output=True, text=True,
                             env={**os.environ, "PYTHONPATH": str(root)})
        return (out.stdout.strip() or None) if out.returncode == 0 else "unavailable"
    import importlib
    module = importlib.import_module(f"studies.{study}")
    return _listed(module.specs(False), str(ROOT)) if hasattr(module, "specs") else None


def fingerprint(study: str, root: Path = ROOT) -> dict[str, str]:
    """sha256 (16 hex digits) of each numerics source of ``study`` in the tree at ``root``, and of its full run's
    case list (key ``studies/NAME.py:full-cases``)."""
    out = {f: _digest(root / f, f.startswith("studies/")) for f in numerics_files(study, root)}
    cases = full_cases(study, root)
    if cases is not None:
        out[f"studies/{study}.py:full-cases"] = cases
    return out


def _git(*args: str, root: Path = ROOT) -> str | None:
    """The output of ``git ARGS`` in ``root``; None where git or the repository is missing."""
    try:
        return subprocess.run(["git", *args], cwd=root, capture_output=True, check=True).stdout.decode()
    except (OSError, subprocess.CalledProcessError):
        return None


def fingerprint_at(study: str, commit: str, root: Path = ROOT) -> dict[str, str]:
    """The same as :func:`fingerprint` for the files as committed in ``commit`` (which numerics sources the study
    had then is decided by the same rules, on the commit's files)."""
    listed = _git("ls-tree", "-r", "--name-only", commit, "--", "ctmrpim", "reference_fem", "studies", root=root)
    if listed is None:
        raise RuntimeError(f"git cannot list commit {commit}")
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        for rel in listed.split():
            data = subprocess.run(["git", "show", f"{commit}:{rel}"], cwd=root, capture_output=True,
                                  check=True).stdout
            (Path(tmp) / rel).parent.mkdir(parents=True, exist_ok=True)
            (Path(tmp) / rel).write_bytes(data)
        return fingerprint(study, Path(tmp))


def sidecar(out_dir: Path, study: str) -> Path:
    """The sidecar of study ``study``'s result in ``out_dir``."""
    return Path(out_dir) / f"{study}{SUFFIX}"


def stamp(out_dir: Path, study: str, commit: str | None = None, root: Path = ROOT, module: str | None = None) -> Path:
    """Write the sidecar of ``study``'s result in ``out_dir``: made by the working tree at ``root`` (the default),
    or, for a result made before stamping existed, by the sources committed in ``commit``; its path. ``module``:
    the ``studies`` module that made the files ``NAME.csv`` / ``NAME.png`` where it is not ``studies/NAME.py``
    (the full report's own figures and tables, :mod:`studies.report.side_runs`)."""
    out_dir = Path(out_dir)
    files = {f"{study}{s}": _sha((out_dir / f"{study}{s}").read_bytes()) for s in OUTPUTS
             if (out_dir / f"{study}{s}").is_file()}
    maker = module or study
    if commit is None:
        sources = fingerprint(maker, root)
        head = (_git("rev-parse", "HEAD", root=root) or "").strip() or None
        dirty = bool(head and (_git("status", "--porcelain", "--", *sources, root=root) or "").strip())
        made = "the working tree at the time of the run"
        found = [__version__]
    else:
        head = (_git("rev-parse", commit, root=root) or commit).strip()
        sources, dirty = fingerprint_at(maker, head, root), False
        made = "stamped after the run: the sources of the commit that committed the result"
        version = "".join(_git("show", f"{head}:ctmrpim/{f}", root=root) or "" for f in ("version.py", "__init__.py"))
        found = [ln.split("=", 1)[1].strip().strip("\"'") for ln in version.splitlines()
                 if ln.startswith("__version__ =")]
    record = {"study": study, **({"module": module} if module else {}), "mode": "full", "files": files,
              "ctmrpim_version": found[0] if found else None, "git_commit": head, "numerics_differ_from_commit": dirty, "made_by": made,
              "stamped": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"), "sources": sources}
    path = sidecar(out_dir, study)
    path.write_text(json.dumps(record, indent=1, sort_keys=True) + "\n")
    return path


@dataclass
class Status:
    """The state of one study's full-mode result: ``current``, ``stale``, ``modified`` or ``unstamped``."""
    study: str
    state: str
    commit: str | None = None
    version: str | None = None
    changed: list[str] = field(default_factory=list)
    rewritten: list[str] = field(default_factory=list)

    @property
    def usable(self) -> bool:
        return self.state == "current"

    def describe(self, shown: int = 4, count: bool = True) -> str:
        """One line: what made the result and what changed since (``count``: how many sources changed; the
        report leaves the count out, which moves with every edit of the sources, and names the first few)."""
        made = (f"made by ctmrpim {self.version} at commit `{(self.commit or '?')[:10]}`" if self.commit
                else f"made by ctmrpim {self.version}" if self.version else "made by unknown code")
        if self.state == "unstamped":
            return "no provenance record (made by unknown code)"
        if self.state == "modified":
            return f"{made}, but {', '.join(self.rewritten)} rewritten since it was stamped"
        if self.state == "current":
            return f"{made}; its numerics sources are unchanged"
        if not self.changed:
            return f"{made}, from a working tree whose numerics sources differed from that commit"
        names = ", ".join(f"`{c}`" for c in self.changed[:shown])
        if not count:
            more = ", and others" if len(self.changed) > shown else ""
            return f"{made}; numerics sources changed since: {names}{more}"
        more = f" and {len(self.changed) - shown} more" if len(self.changed) > shown else ""
        return f"{made}; {len(self.changed)} numerics sources changed since ({names}{more})"


def status(out_dir: Path, study: str, root: Path = ROOT) -> Status:
    """How the result of ``study`` in ``out_dir`` stands against the current sources at ``root``."""
    path = sidecar(out_dir, study)
    if not path.is_file():
        return Status(study, "unstamped")
    rec = json.loads(path.read_text())
    rewritten = [n for n, h in rec["files"].items()
                 if not (Path(out_dir) / n).is_file() or _sha((Path(out_dir) / n).read_bytes()) != h]
    now, then = fingerprint(rec.get("module", study), root), rec["sources"]
    changed = sorted(f for f in set(now) | set(then) if now.get(f) != then.get(f))
    state = "modified" if rewritten else "stale" if changed or rec.get("numerics_differ_from_commit") else "current"
    return Status(study, state, rec.get("git_commit"), rec.get("ctmrpim_version"), changed, rewritten)


def studies_in(out_dir: Path) -> list[str]:
    """The studies with a table, figure or sidecar in ``out_dir``."""
    out_dir = Path(out_dir)
    names = {p.name[:-len(SUFFIX)] for p in out_dir.glob(f"*{SUFFIX}")}
    names |= {p.stem for s in OUTPUTS for p in out_dir.glob(f"*{s}")}
    return sorted(names)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m studies.provenance", description=__doc__.split("\n\n")[0])
    parser.add_argument("out_dir", type=Path, nargs="?", default=Path("reports/full"))
    parser.add_argument("--stamp", metavar="STUDY", action="append", default=[],
                        help="write the sidecar of STUDY's result (repeatable)")
    parser.add_argument("--commit", help="with --stamp: the commit whose sources made the result")
    args = parser.parse_args(argv)
    for name in args.stamp:
        print(f"stamped {stamp(args.out_dir, name, args.commit)}")
    for name in studies_in(args.out_dir):
        s = status(args.out_dir, name)
        print(f"{name}: {s.state}: {s.describe()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
