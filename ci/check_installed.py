"""Check an installed (non-editable) ctmrpim from outside the source tree: every subpackage imports from
the installation, every data file is there, and the command line runs a benchmark with both methods.

Run it with the interpreter of the environment to check, from a folder outside the repository:
    /path/to/venv/bin/python /path/to/repo/ci/check_installed.py
"""
from __future__ import annotations

import importlib
import pkgutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def main() -> int:
    import ctmrpim
    import reference_fem
    import studies

    problems = []
    for package in (ctmrpim, reference_fem, studies):
        where = Path(package.__file__).resolve()
        if REPO in where.parents:
            problems.append(f"{package.__name__} is imported from the source tree ({where}), not the installation")
        source = REPO / package.__name__
        installed = where.parent
        for module in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
            importlib.import_module(module.name)
        # every file of the source package (modules and data) is in the installation
        for f in source.rglob("*"):
            if f.is_file() and "__pycache__" not in f.parts and not (installed / f.relative_to(source)).is_file():
                problems.append(f"missing from the installation: {package.__name__}/{f.relative_to(source)}")
    exe = Path(sys.executable).with_name("ctmrpim")
    with tempfile.TemporaryDirectory() as tmp:
        for args in (["list"], ["run", "cantilever", "--quiet", "--out", "a"],
                     ["run", "cantilever", "--solver", "fem", "--element", "p2", "--quiet", "--out", "b"],
                     ["study", "--help"], ["report", "--help"]):
            proc = subprocess.run([str(exe), *args], cwd=tmp, capture_output=True, text=True)
            if proc.returncode != 0:
                problems.append(f"ctmrpim {' '.join(args)} exited {proc.returncode}: {proc.stderr.strip()[-300:]}")
        for out in ("a", "b"):
            if not (Path(tmp) / out / "summary.json").is_file():
                problems.append(f"ctmrpim run wrote no {out}/summary.json")
    for p in problems:
        print("check_installed:", p, file=sys.stderr)
    print(f"check_installed: {'ok' if not problems else f'{len(problems)} problem(s)'} "
          f"({Path(ctmrpim.__file__).parent})")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
