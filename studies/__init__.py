"""Parameter studies and paper reproductions. Each runs alone (``python -m studies.NAME [--quick]``
or ``ctmrpim study NAME [--quick]``), sends its cases through the sweep executor (cached under
``runs/sweeps/``, resumable, parallel with ``--workers`` or on Dask with ``--scheduler``), and writes
``reports/NAME.csv`` and ``reports/NAME.png``.
"""
from __future__ import annotations

from collections.abc import Callable
from importlib import import_module
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pandas as pd

    from studies.sweep import Sweep

NAMES = ["node_density", "integration_density", "support_radius", "shape_parameter", "parameter_map",
         "time_to_accuracy", "plate_hole_convergence", "integration_schemes", "fe_references",
         "tip_load", "end_moment", "slope_stability",
         "slope_srf_sweep", "slope_relaxation", "footing_bearing", "slope_slide", "column_collapse",
         "column_collapse_settings", "column_collapse_viscosity",
         "nonlinear_schemes"]   # last: it re-uses the nonlinear studies' cases (their cache) with the paper's scheme
#: command-line spelling (dashes) -> module name
ALIASES = {n.replace("_", "-"): n for n in NAMES}


def study(name: str) -> ModuleType:
    """The module of study ``name`` (module name, or its command-line spelling with dashes)."""
    return import_module(f"studies.{ALIASES.get(name, name)}")


def run(name: str, quick: bool = True, out_dir: Path = Path("reports"), sweep: Sweep | None = None,
        progress: Callable[[str], object] = print) -> pd.DataFrame:
    """Run study ``name`` through the sweep executor; its table (also written as CSV and PNG)."""
    from .base import run_study
    return run_study(study(name), quick, out_dir, sweep, progress)
