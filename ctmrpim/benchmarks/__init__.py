"""The paper's benchmark problems, each defined once as a TOML problem file in this folder.

The CLI (`ctmrpim run NAME`), the scikit-fem reference, the studies, the tests and the report all
load them from here, so there is exactly one definition of each problem.
"""
from __future__ import annotations

from pathlib import Path

from ctmrpim.errors import ProblemError
from ctmrpim.problem.case import Case
from ctmrpim.problem.reader import read_case

FOLDER = Path(__file__).parent


def names() -> list[str]:
    return sorted(p.stem for p in FOLDER.glob("*.toml"))


def path(name: str) -> Path:
    p = FOLDER / f"{name}.toml"
    if not p.is_file():
        raise ProblemError(f"unknown benchmark {name!r}; available: {', '.join(names())}")
    return p


def load(name: str, overrides: list[str] | None = None) -> Case:
    return read_case(path(name), overrides)


def data(folder: str, name: str):
    """(k, 2) the measured points of ``data/FOLDER/NAME.csv`` (the folder's README gives the source)."""
    import numpy as np
    return np.loadtxt(FOLDER / "data" / folder / f"{name}.csv", delimiter=",", skiprows=1, ndmin=2)
