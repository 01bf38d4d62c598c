"""The paper's benchmark problems, each defined once as a TOML problem file in this folder.

The CLI (`ctmrpim run NAME`), the scikit-fem reference, the studies, the tests and the report all
load them from here, so there is exactly one definition of each problem.
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from ctmrpim.errors import ProblemError
from ctmrpim.problem.case import Case
from ctmrpim.problem.reader import read_case

if TYPE_CHECKING:
    import numpy as np

FOLDER = Path(__file__).parent


def names() -> list[str]:
    """Sorted names of the benchmark problem files in this folder (the ``NAME`` of ``NAME.toml``)."""
    return sorted(p.stem for p in FOLDER.glob("*.toml"))


def path(name: str) -> Path:
    """Path of benchmark ``name``'s problem file; ProblemError naming the available ones if there is none."""
    p = FOLDER / f"{name}.toml"
    if not p.is_file():
        raise ProblemError(f"unknown benchmark {name!r}; available: {', '.join(names())}")
    return p


def load(name: str, overrides: list[str] | None = None) -> Case:
    """The case of benchmark ``name``, with ``overrides`` (``SECTION.KEY=VALUE`` strings) applied."""
    return read_case(path(name), overrides)


def data(folder: str, name: str) -> np.ndarray:
    """(k, 2) the measured points of ``data/FOLDER/NAME.csv`` (the folder's README gives the source)."""
    import numpy as np
    return np.loadtxt(FOLDER / "data" / folder / f"{name}.csv", delimiter=",", skiprows=1, ndmin=2)
