"""The dynamics sections: the granular column collapse against the experiment (Figs. 26-28), the explicit
solver's momentum conservation and energy ledger, its solver settings and viscosity studies, and what the full
runs measured (read from the committed full-mode tables under ``reports/full/``)."""
from __future__ import annotations

import json
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

import studies
from ctmrpim import benchmarks
from studies import column_collapse, provenance, tolerances
from studies.column_collapse import FINAL, FRONT_STOPPED
from studies.column_collapse_settings import EARLY, early_differences
from studies.report.checks import collapse_checks
from studies.report.full_results import full_rows
from studies.report.markdown import Writer, each, md, sci, span

COLLAPSE_COLUMNS = ["grid", "nodes", "end_time_s", "at_rest", "run_out_m", "height_at_wall_m", "surface_max_dev_m",
                    "surface_mean_dev_m", "failure_line_mean_dist_m", "slope_deg", "run_out_m_at_0.4s",
                    "surface_max_dev_m_at_0.4s", "slope_deg_at_0.4s", "steps", "rebuilds", "dt_min_s",
                    "ms_per_step", "free_particles", "material_balance", "time_s", "status"]
#: the columns of the committed full-mode tables shown in the report
FULL_COLLAPSE_COLUMNS = ["grid", "nodes", "end_time_s", "steps", "rebuilds", "dt_min_s", "free_particles",
                         "run_out_m", "height_at_wall_m", "surface_max_dev_m", "surface_mean_dev_m",
                         "failure_line_mean_dist_m", "slope_deg", "run_out_m_at_0.4s", "surface_max_dev_m_at_0.4s",
                         "plastic_share", "area_change", "ms_per_step", "time_s"]
FULL_VISCOSITY_COLUMNS = ["viscosity_s", "nodes", "end_time_s", "steps", "run_out_m", "height_at_wall_m",
                          "surface_max_dev_m", "surface_mean_dev_m", "failure_line_mean_dist_m", "slope_deg",
                          "viscous_share", "plastic_share", "time_s"]
#: the studies whose full-mode tables this section reads
FULL_STUDIES = ("column_collapse", "column_collapse_viscosity", "column_collapse_settings")
FULL_SETTINGS_COLUMNS = ["variant", "nodes", "early_time_s", "early_front_m", "surface_vs_fixed_step_max_m",
                         "surface_vs_fixed_step_mean_m", "steps", "rebuilds", "dt_min_s", "ms_per_step", "time_s"]


def benchmark_toml(name: str) -> dict:
    """The benchmark's problem file as a dict (its material and settings, as the report quotes them)."""
    return tomllib.loads(benchmarks.path(name).read_text())


def measured_surface() -> np.ndarray:
    """(k, 2) the experiment's final free surface (Bui et al. 2008, digitised)."""
    return benchmarks.data(column_collapse.DATA, "final_surface")


def write_column_collapse(w: Writer, cc: pd.DataFrame, quick: bool) -> None:
    """The column collapse against the experiment (Figs. 26-28)."""
    w("## Dynamics: granular column collapse against the experiment (cf. Figs. 26-28)\n\n")
    w(f"{studies.study('column_collapse').__doc__.strip()}\n\n")
    b = benchmark_toml("column-collapse")
    m, p = b["material"], b["parameters"]
    w(f"The column is {p['W']:g} m x {p['H']:g} m of aluminium rods: E = {m['E'] / 1e6:g} MPa, nu = {m['nu']:g}, "
      f"c = {m['c']:g}, phi = {m['phi']:g} deg, psi = {m['psi']:g}, rho = {m['density']:g} kg/m^3 (benchmark "
      "`column-collapse`). ")
    ok = cc[cc.status == "ok"]
    if len(ok):
        r = ok.iloc[0]
        lo, hi = column_collapse.SLOPE_RANGE
        w(f"The experiment, measured as the runs are: run-out {r.run_out_measured_m:.2f} m, height at the wall "
          f"{measured_height():g} m, surface inclination {r.slope_measured_deg:.3g} deg between x = {lo:g} and "
          f"{hi:g} m, below phi.")
    w("\n\n")
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
    w("**Momentum, and why the explicit solver keeps the paper's CTM.** On the quick column cloud "
      "(`studies/explicit_conservation.py`, no walls; steps, rebuilds and state transfers in the table below) a "
      "free flight under gravity (launched with a translation, a spin and a squeeze that yields the cohesive body) "
      f"keeps p = p0 + M g t to {ff.linear_drift:.1e} and its angular momentum about the centre of mass to "
      f"{ff.angular_drift:.1e}, and an elastic body spinning at {spin.spin_rad_s:g} rad/s ({spin.turns:.1f} turns) "
      f"keeps them to {spin.linear_drift:.1e} and {spin.angular_drift:.1e} (relative; limit "
      f"{tolerances.entry('explicit-momentum-drift')['max']:.0e}, `explicit-momentum-drift`). With the consistent "
      f"scheme's corrected test gradients in the internal force the same flights drift by {ff_vci.linear_drift:.1e} "
      f"/ {ff_vci.angular_drift:.1e} and {spin_vci.linear_drift:.1e} / {spin_vci.angular_drift:.1e}: those "
      f"gradients do not sum to zero at a point, so F_int of the gravity stage's stress has a resultant of "
      f"{vci.resultant:.1e} of sum |f_i| (`ctm`: {ctm.resultant:.1e}) and a torque of {vci.torque:.1e} "
      f"({ctm.torque:.1e}), and the elastic operator of the time step is not symmetric (|A - A^T| / |A| = "
      f"{vci.asymmetry:.1e}, eigenvalues with imaginary parts up to {vci.imaginary:.1e} of the largest; `ctm`: "
      f"{ctm.asymmetry:.1e}, all real, so the LOBPCG estimate of omega_max, "
      f"{abs(ctm.omega_estimate / ctm.omega_max - 1):.1%} below the largest eigenvalue's, is sound). "
      "Explicit analyses therefore integrate with `ctm` and refuse `ctm-vci`.\n\n")
    w(md(flights[[c for c in ("case", "integration", "steps", "rebuilds", "transfers", "linear_drift",
                              "angular_drift", "spin_rad_s", "turns") if c in flights]]))
    w("\n\n")
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


def missed_targets(df: pd.DataFrame) -> dict[int, list[str]]:
    """For each final deposit of ``df`` (index -> names), the experiment's targets (tolerances
    ``column-collapse-*``, as :func:`studies.report.checks.collapse_checks` judges them) it misses."""
    out = {}
    for i in df.index:
        c = collapse_checks(df.loc[[i]])
        c = c[~c.check.str.startswith("column-collapse-energy")]
        if len(c):
            out[i] = [s.split(" (")[0].removeprefix("column-collapse-") for s in c[c["pass"] == "FAIL"].check]
    return out


def surface_deviation(r: pd.Series) -> dict:
    """Where the final surface of run ``r`` (its ``profile``) lies farthest from the measured one, at the measured
    abscissae where either is above the base (as :func:`studies.column_collapse.measures`): x, the measured and
    the run's height there, and the largest distance up to the measured run-out."""
    p = json.loads(r.profile)
    xs, h = np.asarray(p["x"]), np.asarray(p["h"])
    s = measured_surface()
    run = np.interp(s[:, 0], xs, h)
    along = (s[:, 1] > 0) | (run > 0)
    dev = np.where(along, np.abs(run - s[:, 1]), 0.0)
    i = int(np.argmax(dev))
    inside = along & (s[:, 0] <= r.run_out_measured_m + 1e-9)
    return {"x": s[i, 0], "measured": s[i, 1], "run": run[i], "inside": float(dev[inside].max())}


def _collapse_notes(w: Writer, cc: pd.DataFrame, vs: pd.DataFrame | None) -> None:
    """The full-mode collapse at every node count (``cc``), with the viscous share from the viscosity study
    (``vs``)."""
    beta = benchmark_toml("column-collapse")["explicit"]["viscosity"]
    phi = benchmark_toml("column-collapse")["material"]["phi"]
    grids = " / ".join(cc.grid)
    w(md(cc[[c for c in FULL_COLLAPSE_COLUMNS if c in cc]]))
    rest = cc.at_rest.astype(bool)
    w(f"\n\nWith the benchmark's viscosity (beta = {sci(beta)} s) "
      + (f"every node count comes to rest (kinetic energy below 1e-4 of its peak) at {span(cc.end_time_s, '.2f')} s"
         if rest.all() else f"{int(rest.sum())} of {len(cc)} node counts come to rest")
      + f". {grids} nodes against the experiment: run-out "
      f"{each(cc.run_out_m / cc.run_out_measured_m - 1, '+.1%')} of the measured {cc.run_out_measured_m.iloc[0]:.2f} m, "
      f"height at the wall within {(cc.height_at_wall_m / measured_height() - 1).abs().max():.1%} of the measured "
      f"{measured_height():g} m, surface {each(cc.surface_max_dev_m, '.4f')} m from the measured one at worst (mean "
      f"{each(cc.surface_mean_dev_m, '.4f')}), failure line {each(1e3 * cc.failure_line_mean_dist_m, '.1f')} mm "
      f"from the measured one on average, surface inclination {span(cc.slope_deg, '.1f')} deg (measured "
      f"{span(cc.slope_measured_deg, '.3g')}, phi = {phi:g}). ")
    missed = missed_targets(cc)
    n_ok = sum(not v for v in missed.values())
    w(f"{n_ok} of {len(missed)} final deposits meet all four targets of the experiment (`column-collapse-*` in "
      "the tolerances table). ")
    stopped = "run_out_m_at_0.4s"
    if stopped in cc:
        w(f"At t = {FRONT_STOPPED:g} s, when the front has stopped: run-out {each(cc[stopped], '.3f')} m, surface "
          f"within {each(cc['surface_max_dev_m_at_0.4s'], '.4f')} m. ")
    if "profile" in cc:
        d = [surface_deviation(r) for _, r in cc.iterrows()]
        xs = {f"{e['x']:g}" for e in d}
        if len(xs) == 1:
            e = d[0]
            w(f"The largest surface distance lies at the toe for every node count (x = {e['x']:g} m, where the "
              f"measured deposit is still {1e3 * e['measured']:.0f} mm thick and the run's is "
              f"{each((1e3 * x['run'] for x in d), '.0f')} mm); up to the measured run-out the surfaces lie within "
              f"{each((x['inside'] for x in d), '.4f')} m of the measured one. ")
    w(f"Energy: plastic dissipation takes {each(cc.plastic_share, '.0%')} of the work of gravity, the kinetic "
      f"energy left {sci(cc.kinetic_share.max(), '.0e')} of it at most")
    if vs is not None and "viscous_share" in vs:
        at = vs[np.isclose(vs.viscosity_s, beta)]
        if len(at):
            w(f", the viscosity {at.viscous_share.iloc[0]:.0%} (viscosity study, coarse cloud)")
    w(f"; the central-difference identity holds to {sci(cc.energy_balance.abs().max(), '.0e')} and the internal "
      f"work matches the material's accounts to {sci(cc.material_balance.abs().max(), '.0e')}; the mass stays "
      f"{span(cc.mass_kg, '.1f')} kg; the tracked area changes by {each(cc.area_change, '+.1%')} to the end. "
      f"{each(cc.free_particles, 'd')} free particles at the end.\n\n")
    big = cc.loc[cc.nodes.idxmax()]
    w(f"Cost (sweep workers, machine shared): the runs took {each(cc.time_s, '.0f')} s, "
      f"{each(cc.ms_per_step, '.1f')} ms per step; the finest needs {big.steps / cc.steps.min():.1f} times the "
      "steps of the coarsest (the stable step falls with the spacing). "
      "`python performance/bench_column_collapse.py` splits a run's time by phase (its output is not committed).\n\n")


def _viscosity_notes(w: Writer, vs: pd.DataFrame) -> None:
    """The full-mode viscosity study: which viscosities meet the targets."""
    beta = benchmark_toml("column-collapse")["explicit"]["viscosity"]
    w(md(vs[[c for c in FULL_VISCOSITY_COLUMNS if c in vs]]))
    missed = missed_targets(vs)
    meets = [i for i, v in missed.items() if not v and vs.viscosity_s[i] > 0]
    w("\n\n")
    none = vs[vs.viscosity_s == 0]
    if len(none):
        r = none.iloc[0]
        miss = missed.get(none.index[0], [])
        w("Without the viscosity (the paper's model as written, coarse cloud, `viscosity_s` = 0) the surface "
          "layer of the upper slope keeps sliding after the front has stopped, over the resting interior, and the "
          f"column comes to rest only at {r.end_time_s:.2f} s, with run-out {r.run_out_m:.3f} m "
          f"({r.run_out_m / r.run_out_measured_m - 1:+.1%}), height {r.height_at_wall_m:.4f} m "
          f"({r.height_at_wall_m / measured_height() - 1:+.1%}), surface {r.surface_max_dev_m:.4f} m at worst (mean "
          f"{r.surface_mean_dev_m:.4f}), failure line {1e3 * r.failure_line_mean_dist_m:.1f} mm, "
          f"{r.slope_deg:.3g} deg: "
          + (f"it misses the {' and '.join(miss)} target{'s' if len(miss) > 1 else ''}. " if miss
             else "it meets every target. "))
    if meets:
        v = vs.loc[meets]
        w(f"The viscosity is fitted, not derived: beta = {', '.join(map(sci, v.viscosity_s))} s all meet the targets "
          f"(run-out {each(v.run_out_m, '.3f')} m, surface {each(v.surface_max_dev_m, '.4f')} m at worst, "
          f"{each(v.slope_deg, '.1f')} deg, at rest at {each(v.end_time_s, '.2f')} s, the viscosity dissipating "
          f"{each(v.viscous_share, '.0%')} of the work of gravity)")
        for i in [i for i, m in missed.items() if m and vs.viscosity_s[i] > 0]:
            r = vs.loc[i]
            w(f"; {sci(r.viscosity_s)} s misses the {' and '.join(missed[i])} target{'s' if len(missed[i]) > 1 else ''} "
              f"(run-out {r.run_out_m:.3f} m, {r.run_out_m / r.run_out_measured_m - 1:+.1%}; {r.slope_deg:.1f} deg; "
              f"surface {r.surface_max_dev_m:.4f} m)")
        inside = any(np.isclose(vs.viscosity_s[i], beta) for i in meets)
        w(f". The benchmark takes {sci(beta)} s, {'inside' if inside else 'outside'} the range that works.\n\n")


def _settings_notes(w: Writer, st: pd.DataFrame) -> None:
    """The full-mode solver-settings study, compared at ``EARLY``."""
    st = pd.concat([st, early_differences(st)], axis=1)
    w(md(st[[c for c in FULL_SETTINGS_COLUMNS if c in st]]))
    fixed = st[st.variant.str.startswith("dt ")]
    others = st[~st.variant.str.startswith("dt ")].set_index("variant")
    w(f"\n\nSettings (coarse cloud, at t = {EARLY:g} s): the fronts of all {len(st)} runs lie within "
      f"{span(st.early_front_m, '.3f')} m")
    if len(fixed):
        f = fixed.iloc[0]
        limit = tolerances.entry("column-collapse-surface")["max"]
        w(f" and their surfaces within {span(1e3 * others.surface_vs_fixed_step_mean_m, '.1f')} mm on average of "
          f"the run with the paper's fixed step (largest differences "
          f"{span(1e3 * others.surface_vs_fixed_step_max_m, '.1f')} mm)"
          + (": the result does not depend on the rebuild criterion, the re-laying or the time step"
             if others.surface_vs_fixed_step_max_m.max() < limit else "")
          + f". The fixed step takes {f.steps} steps against {span(others.steps, 'd')} and "
          f"{f.time_s / others.time_s.median():.1f} times as long")
    doubled = [v for v in others.index if v.startswith("rebuild_strain") and
               float(v.split()[-1]) > 0.2] if "default" in others.index else []
    for v in doubled:
        w(f"; rebuilding at `{v}` is {others.time_s['default'] / others.time_s[v]:.1f} times faster than the "
          "default")
    w(".\n\n")


def measured_height() -> float:
    """The experiment's final height at the wall (m): the measured surface at x = 0."""
    return float(measured_surface()[0, 1])


def write_full_mode_notes(w: Writer, out_dir: Path, with_figures: bool = True) -> None:
    """What the full runs measured, read from the committed full-mode tables under ``out_dir/full``, with their
    figures unless ``with_figures`` is false (a full report, which shows them in its own sections)."""
    w("### Full mode (measured)\n\n")
    cc, vs, st = (full_rows(out_dir, n) for n in FULL_STUDIES)
    w("Read from the full-mode tables committed under `reports/full/` (`ctmrpim study column-collapse`, the "
      "same for `column-collapse-viscosity` and `column-collapse-settings`).\n\n")
    if cc is None and vs is None and st is None:
        w("No full-mode table is present: nothing to quote.\n\n")
    states = {n: provenance.status(Path(out_dir) / "full", n) for n in FULL_STUDIES
              if (Path(out_dir) / "full" / f"{n}.csv").is_file()}
    old = [n for n, s in states.items() if not s.usable]
    if old:
        w(f"**Not current** ({', '.join(f'{n}: {states[n].state}' for n in old)}): these tables were not made by "
          "the numerics of this code (see 'Provenance of the committed full-mode results'); the numbers below are "
          "what the code that made them measured.\n\n")
    if cc is not None:
        _collapse_notes(w, cc, vs)
    if vs is not None:
        _viscosity_notes(w, vs)
    if st is not None:
        _settings_notes(w, st)
    for name in FULL_STUDIES if with_figures else ():
        if (out_dir / "full" / f"{name}.png").exists():
            w(f"![{name.replace('_', ' ')}, full mode](full/{name}.png)\n\n")
