"""The dynamics sections: the granular column collapse against the experiment (Figs. 26-28), the explicit
solver's momentum conservation and energy ledger, its solver settings and viscosity studies, and what the full
runs measured."""
from __future__ import annotations

from pathlib import Path

import pandas as pd

import studies
from studies import tolerances
from studies.column_collapse import FINAL
from studies.column_collapse_settings import early_differences
from studies.report.markdown import Writer, md

COLLAPSE_COLUMNS = ["grid", "nodes", "end_time_s", "at_rest", "run_out_m", "height_at_wall_m", "surface_max_dev_m",
                    "surface_mean_dev_m", "failure_line_mean_dist_m", "slope_deg", "run_out_m_at_0.4s",
                    "surface_max_dev_m_at_0.4s", "slope_deg_at_0.4s", "steps", "rebuilds", "dt_min_s",
                    "ms_per_step", "free_particles", "material_balance", "time_s", "status"]

#: What the full runs measured (issue 7), kept with the report so the quick report says it too.
COLLAPSE_NOTES = (
    "Measured in full mode (`ctmrpim study column-collapse --out reports/full`, the same for "
    "`column-collapse-viscosity` and `column-collapse-settings`; tables and figures in `reports/full/`). "
    "With the benchmark's viscosity (beta = 5e-6 s) every node count comes to rest (kinetic energy below "
    "1e-4 of its peak) at about 0.62 s. 496 / 1071 / 2016 nodes: run-out 0.353 / 0.357 / 0.356 m "
    "(-2.0 / -0.8 / -1.0 % of 0.36), height at the wall 0.0997 / 0.0999 / 0.0998 m (within 0.3 %), surface "
    "0.0070 m from the measured one at worst at all three (mean 0.0023 / 0.0017 / 0.0015), failure line "
    "4.0 / 4.0 / 4.5 mm from the measured one on average, surface inclination 14.9 / 15.0 / 15.1 deg (measured "
    "14.6-15, phi = 19.8); at rest at 0.614 / 0.625 / 0.616 s after 24317 / 45564 / 75088 steps (dt down to "
    "1.0e-5 / 8.3e-6 / 4.0e-6 s), 101 / 127 / 132 rebuilds (21 / 26 / 26 re-layings), 0 / 1 / 0 free "
    "particles, no failed re-tracking. At t = 0.4 s, when the front has stopped: run-out 0.355 / 0.354 / "
    "0.351 m, surface within 0.0070 / 0.0072 / 0.0070 m. The largest surface distance, 0.007 m at all three, "
    "is at the toe (x = 0.38 m, where the measured deposit is still 7 mm thick and the run's has ended); up "
    "to x = 0.36 m the surfaces lie within 0.0045 / 0.0026 / 0.0024 m of the measured one. Energy (1071 "
    "nodes): gravity did 7.96 J of work; plastic dissipation 6.33 J (80 %), viscous 1.53 J (19 %), contact "
    "with the rough base 0.08 J, kinetic energy left 1.3e-4 J, elastic energy -0.007 J, state transfers "
    "-0.018 J; the internal work matches the material's accounts to 5e-5, the central-difference identity "
    "holds to 5e-15; mass exact (53.0 kg); tracked area +0.3 % at the end.\n\n"
    "Without the viscosity (the paper's model as written; 496 nodes, `viscosity_s` = 0 in the viscosity "
    "study) the surface layer of the upper slope keeps sliding after the front has stopped (at 0.5-0.9 s a "
    "layer one to three nodes thick moves at 0.1-0.5 m/s over the resting interior) and the column comes to "
    "rest only at 1.02 s, with run-out 0.376 m (+4.4 %), height 0.0937 m (-6.3 %), surface 0.0129 m at "
    "worst (mean 0.0063), failure line 9.0 mm, 12.0 deg: the surface target is missed (the earlier runs of "
    "that model to 1 s gave the same picture at 1071 nodes: run-out 0.404 m, +12 %; surface 0.0135 m). The "
    "viscosity is fitted, not derived: beta = 2.5e-6, 5e-6 and 1e-5 s all meet the targets (run-out 0.370 / "
    "0.353 / 0.351 m, surface 0.0058 / 0.0070 / 0.0100 m at worst, 14.0 / 14.9 / 15.8 deg, at rest at 0.77 / "
    "0.61 / 0.59 s, the viscosity dissipating 13 / 18 / 24 % of the work of gravity); 2e-5 s is too much "
    "(run-out 0.322 m, -10.5 %; 17.1 deg; surface 0.0127 m). The benchmark takes 5e-6 s, inside the range "
    "that works; it damps the highest modes of the 1071-node cloud (omega 1.5e4 rad/s at the start, about "
    "9.5e4 where the front thins) at 4-24 % of critical and shortens the stable step there by up to 21 %.\n\n"
    "Settings (496 nodes, at t = 0.3 s): the fronts of all five runs lie within 0.337-0.344 m and their "
    "surfaces within 0.2-0.4 mm on average of the run with the paper's fixed 5 microsecond step (largest "
    "differences 3.8-8.7 mm, at the front): the result does not depend on the rebuild criterion. The fixed "
    "step takes 60000 steps against 12000-13500 and about four times as long; rebuilding at 0.4 instead of "
    "0.2 strain is 1.35 times faster.\n\n"
    "Speed (`python performance/bench_column_collapse.py`, alone on this 2-core machine): the 1071-node "
    "collapse to rest (t = 0.625 s) takes 300 s, within the issue's 10 minutes: 46723 steps (1159 of them the "
    "gravity stage) at 6.4 ms (forces 37 %, material update with the gradient 39 %, rebuilds 17 %, transfers "
    "1.5 %, time-step estimates 1.3 %, output 3.4 %). Before the per-point update and the gradient and force "
    "products were compiled (numba) and before the viscosity, the same run took 781 s to t = 1 s (81434 "
    "steps at 9.6 ms): 1.5 times less per step, 1.7 times fewer steps.\n")


def write_column_collapse(w: Writer, cc: pd.DataFrame, quick: bool) -> None:
    """The column collapse against the experiment (Figs. 26-28)."""
    w("## Dynamics: granular column collapse against the experiment (cf. Figs. 26-28)\n\n")
    w(f"{studies.study('column_collapse').__doc__.strip()}\n\n")
    w(md(cc[[c for c in COLLAPSE_COLUMNS if c in cc]]))
    w("\n\n![column collapse](column_collapse.png)\n\n")
    if quick:
        w("Quick mode runs the coarsest cloud for 0.1 s only (the explicit machinery: gravity stage, gate "
          "removal, rebuilds, energy bookkeeping); the deposit is compared with the experiment in full mode "
          "(below).\n\n")


def write_momentum_conservation(w: Writer, flights: pd.DataFrame, operators: pd.DataFrame, cc: pd.DataFrame) -> None:
    """Why the explicit solver integrates with the paper's CTM, in the numbers of
    :func:`studies.explicit_conservation.measure` (``flights``, ``operators``), and the energy ledger of the
    collapse runs ``cc``."""
    def flight(case: str, integration: str = "ctm") -> pd.Series:
        return flights[(flights.case == case) & (flights.integration == integration)].iloc[0]

    ff, spin = flight("free flight"), flight("spin")
    ff_vci, spin_vci = (flight(c, "ctm-vci (force only)") for c in ("free flight", "spin"))
    ops = operators.set_index("integration")
    ctm, vci = ops.loc["ctm"], ops.loc["ctm-vci"]
    w(f"**Momentum, and why the explicit solver keeps the paper's CTM.** Over {int(ff.steps)} steps on the quick "
      "column cloud (`studies/explicit_conservation.py`, no walls) a free flight under gravity (launched with a "
      f"translation, a spin and a squeeze that yields the cohesive body; {int(ff.rebuilds)} rebuilds, "
      f"{int(ff.transfers)} state transfers) keeps p = p0 + M g t to {ff.linear_drift:.1e} and its angular momentum "
      f"about the centre of mass to {ff.angular_drift:.1e}, and an elastic body spinning at {spin.spin_rad_s:g} rad/s "
      f"({spin.turns:.1f} turns, {int(spin.rebuilds)} rebuilds) keeps them to {spin.linear_drift:.1e} and "
      f"{spin.angular_drift:.1e} (relative; limit {tolerances.entry('explicit-momentum-drift')['max']:.0e}, "
      f"`explicit-momentum-drift`). With the consistent scheme's corrected test gradients in the internal force "
      f"the same flights drift by {ff_vci.linear_drift:.1e} / {ff_vci.angular_drift:.1e} and "
      f"{spin_vci.linear_drift:.1e} / {spin_vci.angular_drift:.1e}: those gradients do not sum to zero at a "
      f"point, so F_int of the gravity stage's stress has a resultant of {vci.resultant:.1e} of sum |f_i| "
      f"(`ctm`: {ctm.resultant:.1e}) and a torque of {vci.torque:.1e} ({ctm.torque:.1e}), and the elastic "
      f"operator of the time step is not symmetric (|A - A^T| / |A| = {vci.asymmetry:.1e}, eigenvalues with "
      f"imaginary parts up to {vci.imaginary:.1e} of the largest; `ctm`: {ctm.asymmetry:.1e}, all real, so the "
      f"power iteration's omega_max, {ctm.omega_power_iteration:.0f} rad/s against {ctm.omega_max:.0f} from the "
      "eigenvalues, is sound). Explicit analyses therefore integrate with `ctm` and refuse `ctm-vci`.\n\n")
    ok = cc[cc.status == "ok"] if "energy_balance" in cc else cc.iloc[:0]
    if not len(ok):
        return
    final = ok[ok.at_rest.astype(bool) | (ok.end_time_s >= FINAL)]
    shown, where = (final, "the runs that reached the end of the flow") if len(final) else (
        ok, f"the run stops at {ok.end_time_s.max():.2g} s, mid-flow (checked only on runs that reach the end of "
            "the flow, full mode)")
    w(f"**Energy ledger** over the work of gravity, {where}: the central-difference balance closes to "
      f"{shown.energy_balance.abs().max():.1e}, the material's accounts to {shown.material_balance.abs().max():.1e} "
      f"(limit {tolerances.entry('column-collapse-energy-balance')['max']:.0e}, "
      "`column-collapse-energy-balance`).\n\n")


def write_collapse_settings(w: Writer, st: pd.DataFrame) -> None:
    """The column collapse under different solver settings (rebuild criterion, fixed step)."""
    w(f"### Solver settings\n\n{studies.study('column_collapse_settings').__doc__.strip()}\n\n")
    st = pd.concat([st, early_differences(st)], axis=1)
    w(md(st[[c for c in ["variant", "nodes", "early_time_s", "early_front_m", "surface_vs_fixed_step_max_m",
                         "surface_vs_fixed_step_mean_m", "steps", "rebuilds", "dt_min_s", "ms_per_step", "time_s",
                         "status"] if c in st]]))
    w("\n\n![column collapse settings](column_collapse_settings.png)\n\n")


def write_collapse_viscosity(w: Writer, vs: pd.DataFrame) -> None:
    """The column collapse against the numerical viscosity."""
    w(f"### Viscosity\n\n{studies.study('column_collapse_viscosity').__doc__.strip()}\n\n")
    w(md(vs[[c for c in ["viscosity_s", "nodes", "end_time_s", "at_rest", "run_out_m", "height_at_wall_m",
                         "surface_max_dev_m", "surface_mean_dev_m", "failure_line_mean_dist_m", "slope_deg",
                         "viscous_share", "steps", "time_s", "status"] if c in vs]]))
    w("\n\n![column collapse viscosity](column_collapse_viscosity.png)\n\n")


def write_full_mode_notes(w: Writer, out_dir: Path) -> None:
    """What the full runs measured, with their figures where ``out_dir/full`` holds them."""
    w(f"### Full mode (measured)\n\n{COLLAPSE_NOTES}\n")
    for name in ("column_collapse", "column_collapse_viscosity", "column_collapse_settings"):
        if (out_dir / "full" / f"{name}.png").exists():
            w(f"![{name.replace('_', ' ')}, full mode](full/{name}.png)\n\n")
