"""The shared command line of every study module: ``python -m studies.NAME [--quick] [--workers N]``."""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Callable

import pandas as pd

from ctmrpim.sweep import Sweep

from .base import CACHE


def main(run: Callable[..., pd.DataFrame], doc: str | None) -> None:
    ap = argparse.ArgumentParser(description=(doc or "").strip().splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the small version CI runs")
    ap.add_argument("--out", default="reports", help="folder for the CSV and PNG (default reports/)")
    ap.add_argument("--workers", type=int, default=1, help="local worker processes")
    ap.add_argument("--scheduler", help="Dask scheduler address (tcp://host:port)")
    a = ap.parse_args()
    sweep = Sweep(CACHE, workers=a.workers, scheduler=a.scheduler)
    print(run(a.quick, Path(a.out), sweep).to_string(index=False))
