"""The verification suite's commands in ``ctmrpim``'s command line: ``study`` and ``report``.

Registered through the entry point ``ctmrpim.commands: studies = "studies.commands:add_commands"``;
the core CLI calls :func:`add_commands` with its subparsers and never imports this package.
"""
from __future__ import annotations

import argparse
import difflib
import os
from pathlib import Path

from ctmrpim.errors import ProblemError


def _sweep(args: argparse.Namespace):
    from studies.base import CACHE
    from studies.sweep import Sweep

    if args.workers < 1:
        raise ProblemError(f"--workers {args.workers}: need at least 1")
    return Sweep(CACHE, workers=args.workers, scheduler=args.scheduler, retry_failed=args.retry_failed)


def _out(args: argparse.Namespace, quick: bool) -> Path:
    """The folder for tables and figures: ``--out``, else ``reports/`` in quick mode and ``reports/full/`` in full
    mode (where the committed full-mode results and their provenance live)."""
    return Path(args.out) if args.out is not None else Path("reports") if quick else Path("reports") / "full"


def cmd_study(args: argparse.Namespace) -> int:
    """``ctmrpim study NAME|all``: run the study (or every one) and print its table without the JSON columns; exit
    status 0, a ProblemError for an unknown name."""
    import studies

    names = studies.NAMES if args.name == "all" else [args.name]
    for name in names:
        if studies.ALIASES.get(name, name) not in studies.NAMES:
            close = difflib.get_close_matches(name, list(studies.ALIASES), n=1)
            raise ProblemError(f"unknown study {name!r}{f' (did you mean {close[0]!r}?)' if close else ''}; "
                               f"available: {', '.join(studies.ALIASES)} or all")
    sweep = _sweep(args)
    for name in names:
        df = studies.run(name, args.quick, _out(args, args.quick), sweep)
        shown = df.drop(columns=[c for c in df if c == "status" or df[c].astype(str).str.startswith(("{", "[")).any()
                                 or c == "folder"])      # curves and profiles (JSON) stay in the CSV
        print(shown.to_string(index=False))
    return 0


def cmd_report(args: argparse.Namespace) -> int:
    """``ctmrpim report``: regenerate the verification report (quick unless ``--full``); exit status 0."""
    from studies.report import make_report

    path = make_report(quick=not args.full, out_dir=_out(args, not args.full), sweep=_sweep(args))
    print(f"wrote {path}")
    return 0


def _sweep_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", help="folder for tables and figures (default reports/ in quick mode, reports/full/ "
                                  "in full mode)")
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                   help="local worker processes for the sweeps (default: one per core; 1 runs in this process)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="run the sweeps on this Dask scheduler instead")
    p.add_argument("--retry-failed", action="store_true", help="recompute cases that failed before")


def add_commands(sub: argparse._SubParsersAction) -> None:
    """Add ``study`` and ``report`` to the ``ctmrpim`` command line's subparsers ``sub``."""
    from studies import ALIASES

    p = sub.add_parser("study", help="run a parameter study (tables and figures under reports/)")
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
