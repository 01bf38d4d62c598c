"""The shared command line of every study module: ``python -m studies.NAME [--quick] [--workers N]``."""
from __future__ import annotations

import argparse
from pathlib import Path
from types import ModuleType

from studies.sweep import Sweep

from .base import CACHE, run_study


def main(module: ModuleType) -> None:
    """``python -m studies.NAME [--quick] [--out DIR] [--workers N] [--scheduler ADDRESS]``: run study ``module`` and
    print its table."""
    ap = argparse.ArgumentParser(description=(module.__doc__ or "").strip().splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the small version CI runs")
    ap.add_argument("--out", default="reports", help="folder for the CSV and PNG (default reports/)")
    ap.add_argument("--workers", type=int, default=1, help="local worker processes")
    ap.add_argument("--scheduler", help="Dask scheduler address (tcp://host:port)")
    a = ap.parse_args()
    sweep = Sweep(CACHE, workers=a.workers, scheduler=a.scheduler)
    print(run_study(module, a.quick, Path(a.out), sweep).to_string(index=False))


def fields_main(module: ModuleType) -> None:
    """``python -m studies.NAME [--quick] [--out DIR]`` for the field studies, which run their cases
    directly (they need fields, not cached summaries) through ``module.run(quick, out_dir)``."""
    ap = argparse.ArgumentParser(description=(module.__doc__ or "").strip().splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the small version CI runs")
    ap.add_argument("--out", default="reports", help="folder for the PNG (default reports/)")
    a = ap.parse_args()
    print(module.run(a.quick, Path(a.out)))
