"""The shared command line of every study module: ``python -m studies.NAME [--quick] [--out DIR]``."""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Callable

import pandas as pd


def main(run: Callable[[bool, Path], pd.DataFrame], doc: str | None) -> None:
    ap = argparse.ArgumentParser(description=(doc or "").strip().splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the small version CI runs")
    ap.add_argument("--out", default="reports", help="folder for the CSV and PNG (default reports/)")
    a = ap.parse_args()
    print(run(a.quick, Path(a.out)).to_string(index=False))
