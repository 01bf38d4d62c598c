"""Command line: ``ctmrpim list | run TARGET | report``.

User mistakes (a bad problem file, an unknown benchmark, a selector that matches nothing) end with
one line on stderr naming the file, key and reason, exit status 2, no traceback, and nothing written.
"""
from __future__ import annotations

import argparse
import difflib
import os
import shutil
import sys
import warnings
from pathlib import Path

from . import benchmarks
from .errors import ProblemError
from .problem_file import Case, load_case
from .result import Result
from .solvers import ELEMENTS, METHODS, solve

def load_target(target: str, overrides: list[str]) -> Case:
    """A benchmark name or a path to a problem file."""
    if target in benchmarks.names():
        return benchmarks.load(target, overrides)
    p = Path(target)
    if p.suffix == ".toml" or p.exists():
        return load_case(p, overrides)
    close = difflib.get_close_matches(target, benchmarks.names(), n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    raise ProblemError(f"{target!r} is neither a benchmark ({', '.join(benchmarks.names())}) nor a problem file{hint}")


def describe(result: Result, case: Case) -> str:
    c, t = result.counts, result.timings
    head = f"{case.problem.name} ({result.method}): {c.get('nodes')} nodes"
    d_c = result.parameters.get("derived", {}).get("d_c") or result.parameters.get("d_c")
    if d_c:
        head += f", d_c = {d_c:.4g}"
    head += f", {c.get('integration_points')} integration points"
    if "support_size" in c:
        s = c["support_size"]
        head += f", support {s['min']}/{s['mean']:.1f}/{s['max']} nodes (min/mean/max)"
    lines = [head]
    perr = result.errors.get("probes", {})
    for name, rec in result.probes.items():
        line = f"  probe {name} ({rec['x']:g}, {rec['y']:g}): ux = {rec['ux']:.6e}, uy = {rec['uy']:.6e}"
        e = perr.get(name, {})
        if "uy" in e:
            line += f"; error in uy {100 * e['uy']:.4g} %"
        elif "u" in e:
            line += f"; error in |u| {100 * e['u']:.4g} %"
        lines.append(line)
    if "l2" in result.errors or "energy" in result.errors:
        lines.append("  relative errors: " + ", ".join(
            f"{k} {100 * result.errors[k]:.4g} %" for k in ("l2", "energy") if k in result.errors))
    fos = result.outcome.get("factor_of_safety")
    if fos is not None:
        lines.append(f"  {c['levels']} strength-reduction levels ({fos['mode']}), {c['newton_iterations']} iterations, "
                     f"{c['cutbacks']} cut-back(s), {c['factorisations']} stiffness factorisation(s)")
        for h in result.history:
            lines.append("    " + _level_line(h))
        if fos["stable"] is not None and fos["failed"] is not None:
            lines.append(f"  factor of safety in [{fos['stable']:.4f}, {fos['failed']:.4f}] "
                         f"(stable, failed by {fos['criterion'].split(':')[0]})")
        else:
            lines.append(f"  factor of safety not bracketed: stable up to {fos['stable']}, failed from {fos['failed']}")
    relaxed = result.outcome.get("relaxation")
    if relaxed is not None:
        state = "at rest" if relaxed["at_rest"] else "NOT at rest"
        lines.append(f"  dynamic relaxation: {state} after {relaxed['steps']} "
                     f"steps (out-of-balance force {relaxed['residual']:.2e} of the loads)")
    limit = result.outcome.get("limit_pressure")
    if limit is not None:
        if limit["failed"] is None:
            lines.append(f"  the full load was carried (peak traction {limit['carried']:.6g}): no limit load below it")
        else:
            lines.append(f"  limit load: carried {limit['carried']:.6g}, not carried {limit['failed']:.6g} "
                         f"(peak traction; "
                         f"load factor {result.outcome['limit_load_factor']['carried']:.5g} .. "
                         f"{result.outcome['limit_load_factor']['failed']:.5g})")
    dyn = result.outcome.get("dynamics")
    if dyn is not None:
        e, dt = dyn["energy"], dyn["dt"]
        rest = "at rest" if dyn["at_rest"] else "NOT at rest"
        lines.append(f"  explicit dynamics: t = {dyn['end_time']:.4g} s ({rest}), "
                     f"{dyn['steps']} steps (+{dyn['stage_steps']} in the gravity stage), dt {dt['min']:.3g} .. "
                     f"{dt['max']:.3g} s, {dyn['rebuilds']} rebuilds ({dyn['state_transfers']} with new CTM points and "
                     f"the state transferred; {dyn['returned_to_yield']} points returned to the yield surface), "
                     f"{dyn['free_particles']['final']} free particle(s), "
                     f"{dyn['points_without_shape_functions']} point(s) dropped")
        lines.append(f"  energy: gravity work {e['gravity_work']:.4g} J = kinetic {e['kinetic']:.3g} + elastic change "
                     f"{e['elastic'] - e['elastic_initial']:.3g} + plastic {e['plastic_dissipation']:.4g} + contact "
                     f"{e['wall_dissipation']:.4g} + damping {e['damping_dissipation']:.3g} (transfers "
                     f"{e['transfer_change']:.3g}; imbalance {100 * e['material_balance']:.2f} %)")
        per = dyn["seconds_per_step"]
        lines.append("  per step: " + ", ".join(f"{k.replace('_', ' ')} {1e3 * v:.2f} ms" for k, v in per.items()))
    if "load_increments" in c:
        line = (f"  {c['load_increments']} load increments, {c['newton_iterations']} Newton iterations, "
                f"{c['cutbacks']} cut-back(s)")
        if "rebuilds" in c:
            line += (f", {c['rebuilds']} rebuilds (boundary re-tracked, RPIM rebuilt; {c['state_transfers']} with new "
                     "CTM points and the state transferred)")
        lines.append(line)
        for h in result.history:
            if "note" in h:
                lines.append(f"  note at load factor {h['load_factor']:.4g}: {h['note']}")
    if c.get("iteration_seconds"):
        lines.append("  of the iterations: " + ", ".join(f"{k} {v:.2f} s" for k, v in c["iteration_seconds"].items()))
    phases = ", ".join(f"{k.replace('_', ' ')} {v:.3f}" for k, v in t.items() if k != "total")
    lines.append(f"  time: {t['total']:.3f} s ({phases})")
    return "\n".join(lines)


def _level_line(h: dict) -> str:
    state = "stable" if h["stable"] else "FAILED"
    if h.get("criterion"):
        state += f" ({h['criterion']})"
    work = (f"{h['iterations']} relaxation steps" if "displacement_history" in h
            else f"{h['iterations']} iterations, {h['cutbacks']} cut-back(s)")
    return f"SRF {h['srf']:.4f}: {state}, {work}, max |u| {h['max_displacement']:.4g}, {h['seconds']:.1f} s"


def cmd_list(args: argparse.Namespace) -> int:
    for name in benchmarks.names():
        case = benchmarks.load(name)
        print(f"{name:16s} {case.resolved['problem']['name']}: {_description(name)}")
    return 0


def _description(name: str) -> str:
    import tomllib
    return tomllib.loads(benchmarks.path(name).read_text()).get("problem", {}).get("description", "")


def cmd_run(args: argparse.Namespace) -> int:
    case = load_target(args.target, args.set or [])
    suffix = "" if args.solver == "ctm-rpim" else f"-fem-{args.element}"
    out = Path(args.out) if args.out else Path("runs") / f"{case.problem.name}{suffix}"
    if args.resume and case.problem.analysis != "explicit":
        raise ProblemError("--resume continues an explicit dynamic run from its checkpoint; this analysis is "
                           f"{case.problem.analysis!r}", key="--resume")
    try:
        progress = None if args.quiet else (lambda level: print("  " + _level_line(level.record()), file=sys.stderr,
                                                                    flush=True))
        result = solve(case, args.solver, args.element, progress=progress, out=out, resume=args.resume,
                       progress_bar=not args.quiet)
    except ProblemError as exc:  # raised while solving, e.g. a selector that matches no node: name the file
        raise exc.at(source=case.source) from None
    paths = write_outputs(result, case, out)
    if not args.quiet:
        print(describe(result, case))
        shown = [p for p in paths if p.parent.name != "series"]
        steps = len(paths) - len(shown)
        print("  wrote " + ", ".join(str(p) for p in shown) + (f" ({steps} increments in series/)" if steps else ""))
    return 0


def write_outputs(result: Result, case: Case, out: Path) -> list[Path]:
    """result.vtu, the increment series (result.pvd + series/*.vtu) where there is one, and
    summary.json last; all or none (a folder this call created is removed again if a write fails, so
    a failed run never leaves a half-written result behind)."""
    from .output import write_series, write_summary, write_vtu

    created = not out.exists()
    paths: list[Path] = []
    try:
        paths.append(write_vtu(result, out))
        for p in write_series(result, out):
            paths.append(p)
        paths.append(write_summary(result, out, case.source))
    except BaseException as exc:
        for p in paths:
            p.unlink(missing_ok=True)
        if created:
            shutil.rmtree(out, ignore_errors=True)
        if isinstance(exc, OSError):  # e.g. --out names an existing file, or a read-only folder
            raise ProblemError(f"cannot write the results to {str(out)!r} ({exc.strerror or exc})",
                               key="--out") from None
        raise
    return paths


def _sweep(args: argparse.Namespace):
    from studies.base import CACHE

    from .sweep import Sweep
    if args.workers < 1:
        raise ProblemError(f"--workers {args.workers}: need at least 1")
    return Sweep(CACHE, workers=args.workers, scheduler=args.scheduler, retry_failed=args.retry_failed)


def cmd_study(args: argparse.Namespace) -> int:
    import studies

    names = studies.NAMES if args.name == "all" else [args.name]
    for name in names:
        if studies.ALIASES.get(name, name) not in studies.NAMES:
            close = difflib.get_close_matches(name, list(studies.ALIASES), n=1)
            raise ProblemError(f"unknown study {name!r}{f' (did you mean {close[0]!r}?)' if close else ''}; "
                               f"available: {', '.join(studies.ALIASES)} or all")
    sweep = _sweep(args)
    for name in names:
        df = studies.run(name, args.quick, Path(args.out), sweep)
        shown = df.drop(columns=[c for c in df if c == "status" or df[c].astype(str).str.startswith(("{", "[")).any()
                                 or c == "folder"])      # curves and profiles (JSON) stay in the CSV
        print(shown.to_string(index=False))
    return 0


def cmd_report(args: argparse.Namespace) -> int:
    from .report import make_report
    path = make_report(quick=not args.full, out_dir=Path(args.out), sweep=_sweep(args))
    print(f"wrote {path}")
    return 0


def _sweep_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", default="reports", help="folder for tables and figures (default reports/)")
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                   help="local worker processes for the sweeps (default: one per core; 1 runs in this process)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="run the sweeps on this Dask scheduler instead")
    p.add_argument("--retry-failed", action="store_true", help="recompute cases that failed before")


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="ctmrpim", description="Adaptive CTM-RPIM meshfree solver and verification suite")
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("list", help="list the benchmark problems")
    p.set_defaults(func=cmd_list)
    p = sub.add_parser("run", help="solve a benchmark or a TOML problem file")
    p.add_argument("target", help="benchmark name (see `ctmrpim list`) or path to a problem file")
    p.add_argument("--out", help="output folder (default runs/NAME)")
    p.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE",
                   help="override a problem-file value, e.g. --set nodes.grid=[65,17] (repeatable)")
    p.add_argument("--solver", choices=METHODS, default="ctm-rpim")
    p.add_argument("--element", choices=ELEMENTS, default="q1", help="FEM element (with --solver fem)")
    p.add_argument("--quiet", action="store_true", help="print nothing on success")
    p.add_argument("--resume", action="store_true",
                   help="explicit dynamics: continue from the checkpoint in the output folder")
    p.set_defaults(func=cmd_run)
    p = sub.add_parser("study", help="run a parameter study (tables and figures under reports/)")
    from studies import ALIASES
    p.add_argument("name", help="study name, or all: " + ", ".join(ALIASES))
    p.add_argument("--quick", action="store_true", help="the small version CI runs")
    _sweep_options(p)
    p.set_defaults(func=cmd_study)
    p = sub.add_parser("report", help="regenerate the verification report")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--quick", action="store_true", help="quick mode (default)")
    g.add_argument("--full", action="store_true", help="every study at the paper's resolution")
    _sweep_options(p)
    p.set_defaults(func=cmd_report)
    return ap


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("always", UserWarning)
        library_show = warnings.showwarning

        def show(message, category, *rest, **kw):
            if issubclass(category, UserWarning):  # ctmrpim's own advice to the user: one plain line
                print(f"ctmrpim: warning: {message}", file=sys.stderr)
            else:
                library_show(message, category, *rest, **kw)

        warnings.showwarning = show
        try:
            return args.func(args)
        except ProblemError as exc:  # the promised single line, even if a library's text held a newline
            print(f"ctmrpim: error: {' '.join(exc.message.splitlines())}", file=sys.stderr)
            return 2
        except KeyboardInterrupt:
            print("ctmrpim: interrupted", file=sys.stderr)
            return 130


if __name__ == "__main__":
    sys.exit(main())
