"""Draw a committed full-mode figure again from its table: ``python -m studies.redraw NAME [NAME ...]``.

A study's ``figure`` function draws its table and computes nothing in it, so the provenance fingerprint
(:mod:`studies.provenance`) leaves it out; after an edit there, this draws ``reports/full/NAME.png`` again from
``reports/full/NAME.csv`` with the current function and records the new figure's hash in the sidecar, and the
result stays as current (or as stale) as it was.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import hashlib
import importlib
import json
from pathlib import Path

import pandas as pd

from studies.base import save_figure
from studies.provenance import sidecar


def redraw(out_dir: Path, study: str) -> Path:
    """Draw ``study``'s figure again from its table in ``out_dir`` and record its hash in the sidecar; its path."""
    out_dir = Path(out_dir)
    path = sidecar(out_dir, study)
    record = json.loads(path.read_text())
    png = out_dir / f"{study}.png"
    save_figure(importlib.import_module(f"studies.{study}").figure(pd.read_csv(out_dir / f"{study}.csv")), png)
    record["files"][png.name] = hashlib.sha256(png.read_bytes()).hexdigest()
    record["figure_redrawn"] = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    path.write_text(json.dumps(record, indent=1, sort_keys=True) + "\n")
    return png


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m studies.redraw", description=__doc__.split("\n\n")[0])
    parser.add_argument("study", nargs="+", help="the study's name (its module in studies/)")
    parser.add_argument("--out", type=Path, default=Path("reports/full"), help="the folder of the results")
    args = parser.parse_args(argv)
    for name in args.study:
        print(f"redrawn {redraw(args.out, name)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
