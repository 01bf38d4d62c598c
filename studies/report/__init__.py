"""The verification report: ``reports/REPORT.md`` with its tables (CSV) and figures (PNG).

It runs every study (``studies/``) through the sweep executor, checks every verified number and
every claim of the paper against the tolerances table, and writes them side by side: the paper's
statement, our value, the analytical reference, the finite-element value, pass/fail.

``make_report`` (here) runs the studies and writes the sections in order; ``checks`` holds the
tolerance checks, ``markdown`` the table formatting, and ``summary``, ``models``, ``linear``,
``large_deformation``, ``stability``, ``dynamics``, ``fe_references`` and ``nonlinear_schemes`` one function per section.
"""
from __future__ import annotations

import io
from pathlib import Path

import studies
from ctmrpim.io.atomic import atomic_write_text
from studies.base import CACHE
from studies.integration_schemes import scheme_table
from studies.report import dynamics, full_figures, large_deformation, linear, models, side_runs, stability, summary
from studies.report.checks import all_checks, claims_table, console_summary
from studies.report.fe_references import write_fe_references
from studies.report.markdown import Progress
from studies.report.nonlinear_schemes import write_nonlinear_schemes
from studies.report.side_runs import SideRuns, study_tables
from studies.sweep import Sweep
from studies.time_to_accuracy import targets_table

__all__ = ["make_report"]


def make_report(quick: bool = True, out_dir: Path = Path("reports"), sweep: Sweep | None = None,
                progress: Progress = print) -> Path:
    """Run every study (quick or full mode) into ``out_dir``, write ``out_dir/REPORT.md`` and print the
    checks through ``progress``; the report's path."""
    out_dir = Path(out_dir)
    sweep = sweep or Sweep(CACHE)
    # every study's cases in one sweep, longest first: the workers stay busy across studies instead of idling at
    # the end of each; the studies then read their cases from the cache
    cases = [spec for name in studies.NAMES for spec in studies.study(name).specs(quick)]
    progress(f"all studies ({'quick' if quick else 'full'}): {len(cases)} cases")
    with SideRuns(quick, out_dir, parallel=sweep.workers > 1 and not sweep.scheduler) as side:
        sweep.run(cases, desc="all studies")
        tables = study_tables(quick, out_dir, sweep, progress)
        _write(quick, out_dir, tables, side, progress)
    return out_dir / "REPORT.md"


def _write(quick: bool, out_dir: Path, tables: dict, side: SideRuns, progress: Progress) -> None:
    """Write ``out_dir/REPORT.md`` from the studies' ``tables`` and the ``side`` runs' results; print the checks."""
    # the sections that quote the committed full-mode results read ``root/full``: beside a quick report
    # (``reports/full``), and in a full one (written to ``reports/full``) the tables this run has just written there
    root = out_dir if quick else out_dir.parent
    checks = all_checks(tables, out_dir if quick else None)   # a full run's collapse checks are its own already
    claim_rows = claims_table(tables)
    head, body = io.StringIO(), io.StringIO()
    summary.write_title(head.write, quick, checks, claim_rows)
    summary.write_claims(head.write, claim_rows, tables)
    summary.write_accuracy_checks(head.write, checks)
    w = body.write          # the provenance goes between the two, once this run's own outputs are stamped
    side.result("models", progress)
    models.write_models(w)
    linear.write_node_density(w, tables["node_density"])
    linear.write_time_to_accuracy(w, targets_table(tables["time_to_accuracy"]))
    linear.write_parameter_studies(w, tables)
    linear.write_plate_hole(w, tables["plate_hole_convergence"])
    linear.write_integration_schemes(w, tables["integration_schemes"], scheme_table(tables["integration_schemes"]))
    write_fe_references(w, tables["fe_references"])
    large_deformation.write_tip_load(w, tables["tip_load"], tables["fe_references"], out_dir if quick else None)
    large_deformation.write_end_moment(w, tables["end_moment"], out_dir if quick else None)
    side.result("deformed_shapes", progress)
    large_deformation.write_deformed_shapes(w)
    stability.write_side_by_side(w, tables["slope_stability"], tables["footing_bearing"])
    stability.write_slope_stability(w, tables["slope_stability"], out_dir if quick else None)
    stability.write_srf_sweep(w, tables["slope_srf_sweep"])
    stability.write_relaxation(w, tables["slope_relaxation"])
    stability.write_footing(w, tables["footing_bearing"], out_dir if quick else None)
    side.result("stability_fields", progress)
    stability.write_stability_fields(w)
    stability.write_slope_slide(w, tables["slope_slide"])
    dynamics.write_column_collapse(w, tables["column_collapse"], quick)
    flights, operators = side.result("explicit_conservation", progress)
    atomic_write_text(out_dir / "explicit_conservation.csv", flights.to_csv(index=False))
    atomic_write_text(out_dir / "explicit_conservation_operators.csv", operators.to_csv(index=False))
    dynamics.write_momentum_conservation(w, flights, operators, tables["column_collapse"])
    dynamics.write_collapse_settings(w, tables["column_collapse_settings"])
    dynamics.write_collapse_viscosity(w, tables["column_collapse_viscosity"])
    dynamics.write_full_mode_notes(w, root, with_figures=quick)
    if quick:
        full_figures.write_full_figures(w, out_dir)
    write_nonlinear_schemes(w, tables["nonlinear_schemes"])
    if not quick:   # the full report's own figures and tables carry their provenance like the studies' results
        for name in side_runs.RUNS:
            side_runs.stamp_outputs(name, out_dir)
    provenance = io.StringIO()
    summary.write_provenance(provenance.write, root)
    atomic_write_text(out_dir / "REPORT.md", head.getvalue() + provenance.getvalue() + body.getvalue())
    progress("\n" + console_summary(checks, claim_rows))

