"""Command line: ``ctmrpim list | run TARGET``, and the commands of installed applications.

A thin layer over the public API (:func:`ctmrpim.load_case`, :func:`ctmrpim.solve`, the outputs of
:mod:`ctmrpim.io`). Further commands come from entry points of the group ``ctmrpim.commands``: each
is a function that adds its subcommands to the parser (the verification suite in ``studies/`` adds
``study`` and ``report``), so this package never imports the application built on it.

Exit status: 0 done; 2 bad input (a bad problem file, an unknown benchmark, a selector that matches
nothing: one line on stderr naming the file, key and reason, no traceback, and nothing written); 3 the solve
did not converge (Newton gave up, dynamic relaxation diverged or did not come to rest, an explicit run
diverged: one line; ``summary.json`` holds the history up to there and ``status.json`` says "not
converged"); 130 interrupted (Ctrl-C) and 143 terminated (SIGTERM): ``status.json`` says "interrupted", no
traceback, no half-written file. The output folder holds one run, with its status record
(:mod:`ctmrpim.io.run_folder`); while a solve runs, its phases and steps are shown on stderr
(:mod:`ctmrpim.progress`; ``--quiet`` silences them). Every warning printed (``ctmrpim: warning: ...``, one
line) is also in the summary's ``notes``.
"""
from __future__ import annotations

import argparse
import contextlib
import math
import os
import shlex
import signal
import sys
import threading
import time
import warnings
from importlib.metadata import entry_points
from pathlib import Path
from typing import Iterator

import ctmrpim.benchmarks as benchmarks
import ctmrpim.methods as methods
from ctmrpim import progress
from ctmrpim.cases import load_case
from ctmrpim.errors import ConvergenceError, ProblemError
from ctmrpim.io.run_folder import RunFolder, default_folder
from ctmrpim.problem.case import Case
from ctmrpim.problem.reader.effects import check_solver_effects, given_keys
from ctmrpim.result import Result
from ctmrpim.solvers.dynamic_relaxation import not_at_rest
from ctmrpim.version import __version__

#: entry-point group of commands that applications add to ``ctmrpim``
COMMANDS = "ctmrpim.commands"
#: exit status of a run interrupted by Ctrl-C (SIGINT), and of one stopped by SIGTERM (128 + the signal's
#: number, as a shell reports a process the signal killed)
INTERRUPTED = 130
TERMINATED = 128 + signal.SIGTERM


class Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``, a batch system's time limit), raised in the main thread like Ctrl-C's
    KeyboardInterrupt, so that a run stopped either way ends the same: its status record says "interrupted",
    the writes under way are undone (every file is written under a temporary name and renamed when
    complete), an explicit run's checkpoint stays for ``--resume``."""


@contextlib.contextmanager
def sigterm_as_interrupt() -> Iterator[None]:
    """Within the ``with`` block SIGTERM raises :class:`Terminated` in this process (from the main thread
    only, where Python runs signal handlers; elsewhere nothing changes). A process forked inside (a sweep's
    workers) still dies of SIGTERM as it would have, and a second SIGTERM does not cut the clean-up short."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    owner = os.getpid()

    def handler(signum: int, frame: object) -> None:
        if os.getpid() != owner:     # a forked worker: the default action, as if no handler were installed
            signal.signal(signum, signal.SIG_DFL)
            os.kill(os.getpid(), signum)
            return
        signal.signal(signum, signal.SIG_IGN)
        raise Terminated

    previous = signal.signal(signal.SIGTERM, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL if previous is None else previous)


def describe(result: Result, case: Case) -> str:
    """The text summary ``ctmrpim run`` prints of a solved case: counts, probes and errors, outcome, timings."""
    c, t = result.counts, result.timings
    head = f"{case.problem.name} ({result.method}): {c.get('nodes')} nodes"
    d_c = result.parameters.get("derived", {}).get("d_c")
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
            f"{k} {_percent(result.errors[k])}" for k in ("l2", "energy") if k in result.errors))
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
            crit = result.outcome.get("limit_criterion")
            if crit is not None:
                lines.append(f"  decided by {crit['decided_by']}; settlement at the carried level "
                             f"{crit['settlement_at_carried']:.4g} (load-weighted mean), criterion: dq/dw at least "
                             f"{crit['limit_slope']:g} of the elastic slope")
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


def _percent(value: float) -> str:
    """A relative error as a percentage; "undefined" where it is not a number (the exact reference is zero)."""
    return f"{100 * value:.4g} %" if math.isfinite(value) else "undefined (the exact value is zero)"


def _level_line(h: dict) -> str:
    state = "stable" if h["stable"] else "FAILED"
    if h.get("criterion"):
        state += f" ({h['criterion']})"
    work = (f"{h['iterations']} relaxation steps" if "displacement_history" in h
            else f"{h['iterations']} iterations, {h['cutbacks']} cut-back(s)")
    return f"SRF {h['srf']:.4f}: {state}, {work}, max |u| {h['max_displacement']:.4g}, {h['seconds']:.1f} s"


def cmd_list(args: argparse.Namespace) -> int:
    """``ctmrpim list``: print each benchmark's name, problem name and description; exit status 0."""
    for name in benchmarks.names():
        case = benchmarks.load(name)
        print(f"{name:16s} {case.resolved['problem']['name']}: {_description(name)}")
    return 0


def _description(name: str) -> str:
    import tomllib
    return tomllib.loads(benchmarks.path(name).read_text()).get("problem", {}).get("description", "")


def _title(case: Case, method: str) -> str:
    """How the progress display names a run: problem, analysis, method and the node specification."""
    nodes = case.resolved.get("nodes", {})
    if "grid" in nodes:
        spec = " x ".join(str(k) for k in nodes["grid"]) + " nodes"
    elif "spacing" in nodes:
        spec = f"node spacing {nodes['spacing']:g}"
    elif "file" in nodes:
        spec = f"nodes from {nodes['file']}"
    else:
        spec = ""
    return f"{case.problem.name} ({', '.join(p for p in (case.problem.analysis, method, spec) if p)})"


def cmd_run(args: argparse.Namespace) -> int:
    """``ctmrpim run TARGET``: solve a benchmark or problem file into its output folder, print a summary; exit
    status 0, or 3 when the solve did not converge (bad input raises a ProblemError: 2)."""
    if args.out is not None and not args.out.strip():
        raise ProblemError("--out '' names no folder: give a folder, or leave --out out for the default", key="--out")
    case = load_case(args.target, args.set or [])
    element = methods.element_of(methods.get(args.solver), args.element)
    try:
        check_solver_effects(given_keys("method", case.resolved, case.defaults), _set_keys(args.set, "method"),
                             args.solver)
    except ProblemError as exc:
        raise exc.at(source=case.source) from None
    suffix = "" if args.solver == methods.DEFAULT else f"-{args.solver}" + (f"-{element}" if element else "")
    out = Path(args.out) if args.out else default_folder(args.target, case, args.target in benchmarks.names(),
                                                         suffix)
    if args.resume and case.problem.analysis != "explicit":
        raise ProblemError("--resume continues an explicit dynamic run from its checkpoint; this analysis is "
                           f"{case.problem.analysis!r}", key="--resume")
    method = args.solver + (f"-{element}" if element else "")
    folder = RunFolder(out, command=shlex.join(["ctmrpim", *args.argv]), source=case.source, method=method,
                       resume=args.resume, notes=args.notes)
    folder.start()
    reporter = progress.SILENT if args.quiet else progress.Progress(title=_title(case, method), name=case.problem.name)
    try:
        with progress.reporting(reporter):
            levels = None if args.quiet else (lambda level: reporter.line("  " + _level_line(level.record())))
            result = methods.solve(case, args.solver, args.element, progress=levels, out=out, resume=args.resume,
                                   progress_bar=not args.quiet)
            if (unsettled := not_at_rest(result.outcome, result.history, case.relaxation)) is not None:
                raise unsettled      # a relaxation that never came to rest has not found the static answer
            start = time.perf_counter()
            paths = folder.write_result(result, case)
            reporter.phase("output", time.perf_counter() - start)
    except ConvergenceError as exc:      # accepted input, a solve that gave up: keep what it got through
        exc = exc.at(source=case.source)
        summary = folder.not_converged(exc, case)
        print(f"ctmrpim: not converged: {' '.join(exc.message.splitlines())} (the history up to there is in "
              f"{summary})", file=sys.stderr)
        return 3
    except ProblemError as exc:  # raised while solving, e.g. a selector that matches no node: name the file
        folder.discard()
        raise exc.at(source=case.source) from None
    except KeyboardInterrupt as exc:     # Ctrl-C, or SIGTERM (Terminated)
        terminated = isinstance(exc, Terminated)
        folder.finish("interrupted", TERMINATED if terminated else INTERRUPTED,
                      error="terminated (SIGTERM)" if terminated else "interrupted")
        raise
    except BaseException as exc:     # a bug: the record says so, the traceback follows
        folder.finish("failed", 1, error=f"{type(exc).__name__}: {exc}")
        raise
    if not args.quiet:
        print(describe(result, case))
        shown = [p for p in paths if p.parent.name != "series"]
        steps = len(paths) - len(shown)
        print("  wrote " + ", ".join(str(p) for p in shown) + (f" ({steps} increments in series/)" if steps else ""))
    return 0


def _set_keys(overrides: list[str] | None, section: str) -> list[str]:
    """The keys of ``section`` that ``--set section.key=value`` items set (malformed ones were refused when
    the case was read)."""
    dotted = (item.partition("=")[0].partition(".") for item in overrides or [])
    return [key.strip() for name, _, key in dotted if name.strip() == section]


def build_parser() -> argparse.ArgumentParser:
    """The ``ctmrpim`` argument parser: ``list``, ``run`` and the commands of the ``ctmrpim.commands`` entry points."""
    ap = argparse.ArgumentParser(prog="ctmrpim", description="Adaptive CTM-RPIM meshfree solver and verification suite")
    ap.add_argument("--version", action="version", version=f"ctmrpim {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("list", help="list the benchmark problems")
    p.set_defaults(func=cmd_list)
    p = sub.add_parser("run", help="solve a benchmark or a TOML problem file")
    p.add_argument("target", help="benchmark name (see `ctmrpim list`) or path to a problem file")
    p.add_argument("--out", help="output folder, holding this run only: an earlier run's files there are removed "
                                 "(default runs/NAME for a benchmark, runs/STEM-HASH for a problem file)")
    p.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE",
                   help="override a problem-file value, e.g. --set nodes.grid=[65,17] (repeatable)")
    p.add_argument("--solver", choices=methods.names(), default=methods.DEFAULT,
                   help="the method (default ctm-rpim; fem: the scikit-fem reference; fenicsx: dolfinx 0.5 in the "
                        "system Python, on the same mesh)")
    p.add_argument("--element", help="element of a finite-element method: q1, p1 or p2 for fem, also q2 and p3 for "
                                     "fenicsx (default q1)")
    p.add_argument("--quiet", action="store_true", help="print nothing on success (no progress either)")
    p.add_argument("--resume", action="store_true",
                   help="explicit dynamics: continue from the checkpoint in the output folder")
    p.set_defaults(func=cmd_run)
    for ep in entry_points(group=COMMANDS):     # e.g. `study` and `report` of the verification suite
        ep.load()(sub)
    return ap


def main(argv: list[str] | None = None) -> int:
    """Run the command line on ``argv`` (default ``sys.argv[1:]``); exit status 0, 2 on a ProblemError, 3 when a
    solve did not converge, 130 when interrupted (Ctrl-C), 143 when terminated (SIGTERM)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    args = build_parser().parse_args(argv)
    args.argv = argv
    args.notes = []      # every warning shown, for the summary's notes
    with warnings.catch_warnings():
        warnings.simplefilter("always", UserWarning)
        library_show = warnings.showwarning

        def show(message, category, *rest, **kw):
            if issubclass(category, UserWarning):  # ctmrpim's own advice to the user: one plain line
                if str(message) not in args.notes:
                    args.notes.append(str(message))
                reporter = progress.current()
                if isinstance(reporter, progress.Progress) and reporter.live:   # not through the live line
                    reporter.line(f"ctmrpim: warning: {message}")
                else:
                    print(f"ctmrpim: warning: {message}", file=sys.stderr)
            else:
                library_show(message, category, *rest, **kw)

        warnings.showwarning = show
        try:
            with sigterm_as_interrupt():
                return args.func(args)
        except ProblemError as exc:  # the promised single line, even if a library's text held a newline
            print(f"ctmrpim: error: {' '.join(exc.message.splitlines())}", file=sys.stderr)
            return 2
        except Terminated:
            print("ctmrpim: terminated (SIGTERM)", file=sys.stderr)
            return TERMINATED
        except KeyboardInterrupt:
            print("ctmrpim: interrupted", file=sys.stderr)
            return INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
