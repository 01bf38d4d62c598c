"""What every study shares: run its cases through the sweep executor, tabulate, write CSV and PNG.

A study module defines ``NAME``, ``TITLE``, ``specs(quick) -> list[CaseSpec]`` (each spec labelled
with the study's coordinates), ``figure(table) -> Figure`` and optionally ``extra(summary) -> dict``
for columns of its own (``extra(summary, folder)`` where it also reads the files a case wrote into its
folder, such as an explicit run's time series); :func:`run_study` (or ``studies.run(name)``) does the rest.
"""
from __future__ import annotations

import inspect
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

import pandas as pd

from ctmrpim.errors import ProblemError
from ctmrpim.io.atomic import atomic_write, atomic_write_text
from studies.sweep import CaseOutcome, CaseSpec, Sweep

if TYPE_CHECKING:
    import numpy as np
    from matplotlib.figure import Figure

CACHE = Path("runs") / "sweeps"   # one folder per case, named by the hash of its resolved input


def method_name(spec: CaseSpec, summary: dict | None = None) -> str:
    """The method column of a case's row: ``fem-ELEMENT``, or ``ctm-rpim``, ``ctm-rpim-quadratic`` with
    ``-vci`` appended for the consistent integration (read from the ``summary`` where the case ran, else
    from the overrides)."""
    if spec.solver == "fem":
        return f"fem-{spec.element}"
    given = [o.replace(" ", "") for o in spec.overrides]
    name = "ctm-rpim-quadratic" if 'method.polynomial="quadratic"' in given else "ctm-rpim"
    if summary is not None:
        consistent = summary["parameters"].get("method", {}).get("integration") == "ctm-vci"
    else:
        consistent = 'method.integration="ctm-vci"' in given
    return name + "-vci" if consistent else name


def metrics(outcome: CaseOutcome, extra: Callable[..., dict[str, Any]] | None = None) -> dict[str, Any]:
    """The numbers a study tabulates from one case's summary.json (plus ``extra(summary)``)."""
    s = outcome.summary
    row: dict[str, Any] = {**outcome.spec.label_dict(), "method": method_name(outcome.spec, s),
                           "status": outcome.status}
    if s is None:
        return {**row, "error_message": outcome.error}
    errors = s.get("errors", {})
    tip = errors.get("probes", {}).get("tip", {})
    derived = s["parameters"].get("derived", {})
    row.update(nodes=s["counts"]["nodes"], integration_points=s["counts"]["integration_points"],
               d_c=derived.get("d_c"),
               tip_error=tip.get("uy"), l2_error=errors.get("l2"), energy_error=errors.get("energy"),
               time_s=s["timings"]["total"])
    if extra is not None:
        row.update(extra(s, outcome.folder) if len(inspect.signature(extra).parameters) == 2 else extra(s))
    return row


def run_study(module: ModuleType, quick: bool = True, out_dir: Path = Path("reports"),
              sweep: Sweep | None = None, progress: Callable[[str], object] = print) -> pd.DataFrame:
    """Run the study ``module``'s cases (quick or full) through ``sweep`` (default: a local one cached under
    ``runs/sweeps``), report through ``progress``, write ``NAME.csv`` and ``NAME.png`` to ``out_dir``; its table,
    one row per case (:func:`metrics`)."""
    sweep = sweep or Sweep(CACHE)
    specs = module.specs(quick)
    progress(f"study {module.NAME} ({'quick' if quick else 'full'}): {len(specs)} cases")
    outcomes = sweep.run(specs, desc=module.NAME)
    df = pd.DataFrame([metrics(o, getattr(module, "extra", None)) for o in outcomes])
    failed = df[df.status != "ok"]
    for _, r in failed.iterrows():
        progress(f"  case failed: {r.to_dict()}")
    progress(f"  {len(specs) - sweep.computed} cached, {sweep.computed} computed, {len(failed)} failed")
    if len(failed) == len(df):   # nothing to tabulate or plot: say so instead of an empty figure's traceback
        first = failed.iloc[0].to_dict() if len(failed) else {}
        raise ProblemError(f"study {module.NAME}: all {len(df)} cases failed (first: status {first.get('status')!r}"
                           f"{', ' + str(first['error_message']) if first.get('error_message') else ''}); nothing written")
    out_dir = Path(out_dir)
    atomic_write_text(out_dir / f"{module.NAME}.csv", df.to_csv(index=False))
    fig = module.figure(df)
    save_figure(fig, out_dir / f"{module.NAME}.png")
    if not quick:   # a full-mode result records the code that made it (studies/provenance.py)
        from studies.provenance import stamp
        stamp(out_dir, module.NAME)
    return df


def save_figure(fig: Figure, path: Path) -> Path:
    """Write a figure as PNG atomically and release it."""
    import matplotlib.pyplot as plt

    atomic_write(path, lambda p: fig.savefig(p, format="png", dpi=110))
    plt.close(fig)
    return path


def finished(fig: Figure, axes: np.ndarray, which: str = "major", fontsize: int = 8) -> Figure:
    """The common finish of a study figure: grid and legend on every axis of ``axes`` (an array of them), tight
    layout; the figure."""
    for ax in axes.ravel():
        ax.grid(True, which=which, alpha=0.3)
        ax.legend(fontsize=fontsize)
    fig.tight_layout()
    return fig


def new_figure(ncols: int = 1, width: float = 5.5, nrows: int = 1) -> tuple[Figure, np.ndarray]:
    """A new figure (Agg backend) with ``nrows`` rows of ``ncols`` axes, each ``width`` x 4 inches: (figure, axes
    (nrows, ncols))."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt.subplots(nrows, ncols, figsize=(width * ncols, 4 * nrows), squeeze=False)
