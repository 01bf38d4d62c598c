"""Column collapse: does the deposit depend on the solver's own choices? (issue 7)

On the coarse cloud (31 x 16 nodes) the collapse is repeated with the rebuild criterion
(``explicit.rebuild_strain``: RPIM rebuilt on the current nodes once a point has been strained this
much since the last rebuild) halved and doubled, with new CTM points laid twice as often
(``explicit.relay_strain``), and with the paper's fixed time step of 5 microseconds instead of the
stable step from the LOBPCG estimate (``explicit.dt``). The runs go to t = 0.3 s, the middle of the
flow, while the front still moves, and are compared there: the front (farthest x where the surface is
0.01 m high) and the largest vertical distance of each surface from the fixed-step run's. Quick mode (CI): two rebuild criteria for 0.1 s.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from ctmrpim.reference.deposit import surface_profile
from studies.sweep import CaseSpec

from . import column_collapse

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NAME = "column_collapse_settings"
TITLE = "Column collapse: deposit against the rebuild criterion and the time step (496 nodes)"
GRID = "nodes.grid=[31, 16]"
#: the fixed-step run (40 times the steps) is compared with the others at this time (s), the flow's middle
EARLY = 0.3
#: abscissae of the surfaces compared at EARLY (m): one grid for every cloud
EARLY_XS = np.arange(0.0, 0.5, 0.002)
VARIANTS = {"full": [("default", ()), ("rebuild_strain 0.1", ("explicit.rebuild_strain=0.1",)),
                     ("rebuild_strain 0.4", ("explicit.rebuild_strain=0.4",)),
                     ("relay_strain 0.5", ("explicit.relay_strain=0.5",)),
                     ("dt 5 us (paper)", ("explicit.dt=5e-6",))],
            "quick": [("default", ()), ("rebuild_strain 0.4", ("explicit.rebuild_strain=0.4",))]}


def specs(quick: bool) -> list[CaseSpec]:
    """One case per solver-setting variant on the coarse cloud to t = ``EARLY`` (quick: two rebuild criteria on
    16 x 9 nodes for 0.1 s)."""
    grid = ("nodes.grid=[16, 9]",) + column_collapse.QUICK if quick else (GRID, f"explicit.duration={EARLY}")
    return [CaseSpec("column-collapse", grid + extra, labels=(("variant", name),))
            for name, extra in VARIANTS["quick" if quick else "full"]]


def extra(summary: dict, folder: Path) -> dict:
    """:func:`column_collapse.extra` plus the surface at ``EARLY`` (time, front, profile on ``EARLY_XS``), read
    from the run's ``folder``."""
    t, mesh = column_collapse.state_at(folder, EARLY)
    h = surface_profile(mesh.points[:, :2], column_collapse.boundary_edges(mesh), EARLY_XS)
    front = column_collapse.run_out(EARLY_XS, h, column_collapse.RUN_OUT_THICKNESS)
    return {**column_collapse.extra(summary, folder), "early_time_s": t, "early_front_m": front,
            "early_profile": json.dumps(h.round(6).tolist())}


def early_differences(df: pd.DataFrame) -> pd.DataFrame:
    """Largest and mean vertical distance (m) of each run's surface at EARLY from the fixed-step (paper)
    run's, over the abscissae where either surface is above the base."""
    ok = df[df.status == "ok"]
    ref = ok[ok.variant.str.startswith("dt ")]
    out = pd.DataFrame(np.nan, index=df.index, columns=["surface_vs_fixed_step_max_m", "surface_vs_fixed_step_mean_m"])
    if ref.empty or "early_profile" not in df:
        return out
    base = np.array(json.loads(ref.iloc[0].early_profile))
    for i, p in df.early_profile.items():
        if isinstance(p, str):
            h = np.array(json.loads(p))
            d = np.abs(h - base)[(h > 0) | (base > 0)]
            out.loc[i] = [d.max(), d.mean()]
    return out


def figure(df: pd.DataFrame) -> Figure:
    """The surface of each variant at ``EARLY``, and each variant's wall time."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(14, 4), gridspec_kw={"width_ratios": [2.5, 1]})
    ok = df[df.status == "ok"]
    ax = axes[0]
    for _, r in ok.iterrows():
        ax.plot(EARLY_XS, json.loads(r.early_profile), lw=1.2,
                label=f"{r.variant}: front {r.early_front_m:.3f} m at t = {r.early_time_s:.2f} s")
    ax.set(xlabel="x (m)", ylabel="surface height (m)", xlim=(0, 0.5), ylim=(0, 0.11),
           title=f"surface at t = {EARLY} s (496 nodes)")
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    ax = axes[1]
    if len(ok):
        ax.barh(ok.variant, ok.time_s)
    ax.set(xlabel="wall time (s)", ylabel="setting", title="cost")
    ax.tick_params(axis="y", labelsize=7)
    ax.grid(True, alpha=0.3)
    fig.suptitle(TITLE)
    fig.tight_layout()
    return fig


if __name__ == "__main__":
    from .cli import main
    main(sys.modules[__name__])
