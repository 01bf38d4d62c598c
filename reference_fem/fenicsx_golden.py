"""Golden FEniCSx results: every linear benchmark, a user's problem file and the neo-Hookean tip-load solved by
dolfinx once and committed (``reference_fem/golden/NAME.json``), so that scikit-fem is compared with FEniCSx on
every machine, with or without dolfinx.

Each file holds the case (target, overrides, element), the versions that made it, the mesh itself (so that a
change of the node generation is caught rather than compared against the wrong mesh), the probes, the strain
energy, the errors against the exact solution, the nodal displacement and the worker's wall time.

    python -m reference_fem.fenicsx_golden                compare scikit-fem with the golden files
    python -m reference_fem.fenicsx_golden --check        solve with FEniCSx now, show the differences (writes nothing)
    python -m reference_fem.fenicsx_golden --regenerate   solve with FEniCSx now and rewrite the golden files
    python -m reference_fem.fenicsx_golden --overhead     the bridge's cost per run, with a cold and a warm JIT cache

Differences (:func:`differences`) are relative: probe displacements and the nodal displacement over the
largest nodal displacement, probe stresses over the largest probe stress (the stress of both codes is the
L2 projection onto the element's own continuous space, evaluated at the probe), the strain energy over
itself, and the errors against the exact solution as absolute differences of the relative errors.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ctmrpim.cases import load_case
from ctmrpim.methods import solve
from ctmrpim.result import Result
from reference_fem.fenicsx_payload import fem_mesh

FOLDER = Path(__file__).resolve().with_name("golden")


@dataclass(frozen=True)
class GoldenCase:
    """One golden case: a benchmark name or a problem file beside the golden files, overrides, element."""
    name: str
    target: str
    overrides: tuple[str, ...]
    element: str

    @property
    def linear(self) -> bool:
        return not self.target.startswith("tip-load")

    def load(self):
        """The case (a target ending in .toml is a file in the golden folder)."""
        target = str(FOLDER / self.target) if self.target.endswith(".toml") else self.target
        return load_case(target, list(self.overrides))

    @property
    def path(self) -> Path:
        return FOLDER / f"{self.name}.json"


GRID = ("nodes.grid=[17, 5]",)
CASES = (
    GoldenCase("cantilever-q1", "cantilever", GRID, "q1"),
    GoldenCase("cantilever-p1", "cantilever", GRID, "p1"),
    GoldenCase("cantilever-p2", "cantilever", GRID, "p2"),
    GoldenCase("cantilever-cloud-p1", "cantilever", ("nodes.spacing=2.0",), "p1"),
    GoldenCase("plate-hole-p1", "plate-hole", (), "p1"),
    GoldenCase("plate-hole-p2", "plate-hole", (), "p2"),
    GoldenCase("self-weight-q1", "self-weight", (), "q1"),
    GoldenCase("self-weight-p2", "self-weight", (), "p2"),
    GoldenCase("manufactured-p1", "manufactured", (), "p1"),
    GoldenCase("manufactured-p2", "manufactured", (), "p2"),
    GoldenCase("patch-p1", "patch", (), "p1"),
    GoldenCase("patch-p2", "patch", (), "p2"),
    GoldenCase("bracket-p2", "bracket.toml", (), "p2"),
    GoldenCase("tip-load-q1", "tip-load", (), "q1"),
    GoldenCase("tip-load-p2", "tip-load", (), "p2"),
)
BY_NAME = {c.name: c for c in CASES}


def record(result: Result) -> dict:
    """What a golden file keeps of a solution (and what it is compared on)."""
    return {"probes": result.probes, "strain_energy": result.outcome["strain_energy"],
            "errors": {k: v for k, v in result.errors.items() if k != "probes"},
            "u": result.u.tolist()}


def golden_record(gc: GoldenCase, result: Result, seconds: float) -> dict:
    """The content of ``gc``'s golden file from its FEniCSx ``result``."""
    fm = fem_mesh(gc.load(), gc.element)
    return {"case": {"target": gc.target, "overrides": list(gc.overrides), "element": gc.element},
            "versions": result.outcome["fenicsx"], "seconds": round(seconds, 2),
            "mesh": {"cell_type": fm.cell_type, "points": fm.mesh.p.T.tolist(), "cells": fm.cells.tolist()},
            **record(result)}


def read(gc: GoldenCase) -> dict:
    """The golden file of ``gc``."""
    return json.loads(gc.path.read_text())


def write(gc: GoldenCase, content: dict) -> None:
    """Write the golden file: one top-level key per line (readable diffs, full float precision)."""
    lines = [f" {json.dumps(k)}: {json.dumps(v, separators=(',', ':'))}" for k, v in content.items()]
    gc.path.write_text("{\n" + ",\n".join(lines) + "\n}\n")


def mesh_change(gc: GoldenCase, golden: dict) -> str | None:
    """Why the mesh scikit-fem builds now is not the golden file's (None when it is the same)."""
    fm = fem_mesh(gc.load(), gc.element)
    g = golden["mesh"]
    points, cells = np.array(g["points"]), np.array(g["cells"])
    if fm.cell_type != g["cell_type"] or fm.mesh.p.T.shape != points.shape or fm.cells.shape != cells.shape:
        return f"{gc.name}: the mesh has changed ({len(points)} -> {fm.mesh.p.shape[1]} vertices)"
    scale = np.abs(points).max()
    if not (np.allclose(fm.mesh.p.T, points, rtol=0, atol=1e-12 * scale) and np.array_equal(fm.cells, cells)):
        return f"{gc.name}: the mesh has changed (same size, other vertices or cells)"
    return None


def differences(a: dict, b: dict) -> dict[str, float]:
    """Relative differences of two records (:func:`record`) on the same mesh (module docstring)."""
    ua, ub = np.array(a["u"]), np.array(b["u"])
    u_scale = np.linalg.norm(ub, axis=1).max()
    probes = list(b["probes"])
    s_scale = max([abs(b["probes"][p][k]) for p in probes for k in ("sxx", "syy", "sxy")], default=0.0)
    out = {
        "u_nodes": float(np.linalg.norm(ua - ub, axis=1).max() / u_scale),
        "u_probes": max([float(np.hypot(a["probes"][p]["ux"] - b["probes"][p]["ux"],
                                        a["probes"][p]["uy"] - b["probes"][p]["uy"]) / u_scale) for p in probes],
                        default=0.0),
        "stress_probes": max([abs(a["probes"][p][k] - b["probes"][p][k]) / s_scale
                              for p in probes for k in ("sxx", "syy", "sxy")], default=0.0),
        "energy": abs(a["strain_energy"] - b["strain_energy"]) / abs(b["strain_energy"]),
    }
    shared = [k for k in b["errors"] if k in a["errors"] and b["errors"][k] is not None]
    if shared:
        out["errors"] = max(abs(a["errors"][k] - b["errors"][k]) for k in shared)
    return out


def solve_timed(gc: GoldenCase, method: str) -> tuple[Result, float]:
    """``gc`` solved by ``method`` ("fem" or "fenicsx"), and the wall time."""
    start = time.perf_counter()
    result = solve(gc.load(), method, gc.element)
    return result, time.perf_counter() - start


def _line(name: str, diff: dict[str, float], extra: str = "") -> str:
    return f"{name:22s} " + "  ".join(f"{k} {v:.1e}" for k, v in diff.items()) + extra


def _compare_scikit(cases: list[GoldenCase]) -> int:
    status = 0
    for gc in cases:
        golden = read(gc)
        change = mesh_change(gc, golden)
        if change:
            print(change + "; regenerate with --regenerate", file=sys.stderr)
            status = 1
            continue
        result, _ = solve_timed(gc, "fem")
        print(_line(gc.name, differences(record(result), golden)))
    return status


def _run_fenicsx(cases: list[GoldenCase], regenerate: bool) -> int:
    total, fenicsx = time.perf_counter(), 0.0
    for gc in cases:
        result, seconds = solve_timed(gc, "fenicsx")
        fenicsx += seconds
        new = golden_record(gc, result, seconds)
        reference, _ = solve_timed(gc, "fem")
        versus = differences(record(reference), new)
        if gc.path.exists():
            old = read(gc)
            change = mesh_change(gc, old)
            diff = "new mesh" if change else "  ".join(f"{k} {v:.1e}" for k, v in differences(new, old).items())
            extra = f"  | vs the golden file: {diff}"
        else:
            extra = "  | no golden file yet"
        print(_line(gc.name, versus, f"  ({seconds:.1f} s){extra}"), flush=True)
        if regenerate:
            write(gc, new)
    print(f"{len(cases)} cases in {time.perf_counter() - total:.1f} s, of which FEniCSx {fenicsx:.1f} s"
          + (" (golden files rewritten)" if regenerate else ""))
    return 0


def overhead(gc: GoldenCase = BY_NAME["cantilever-p2"]) -> dict[str, float]:
    """The bridge's cost on ``gc``: the whole run and the worker's phases with an empty JIT cache (cold) and
    again with the cache it filled (warm), against the scikit-fem solve of the same case."""
    out: dict[str, float] = {"scikit-fem": solve_timed(gc, "fem")[1]}
    saved = os.environ.get("XDG_CACHE_HOME")
    with tempfile.TemporaryDirectory(prefix="ctmrpim-jit-") as cache:
        os.environ["XDG_CACHE_HOME"] = cache
        try:
            for label in ("cold", "warm"):
                result, seconds = solve_timed(gc, "fenicsx")
                out[f"{label} total"] = seconds
                out[f"{label} start (interpreter + imports + exit)"] = (result.timings["fenicsx_import"]
                                                                        + result.timings["bridge"])
        finally:
            if saved is None:
                del os.environ["XDG_CACHE_HOME"]
            else:
                os.environ["XDG_CACHE_HOME"] = saved
    out["JIT (cold - warm)"] = out["cold total"] - out["warm total"]
    return out


def main(argv: list[str] | None = None) -> int:
    """The command line (module docstring); exit status 0, 1 where a golden mesh has changed."""
    ap = argparse.ArgumentParser(prog="python -m reference_fem.fenicsx_golden", description=__doc__.split("\n\n")[0])
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--check", action="store_true", help="solve with FEniCSx and show the differences")
    mode.add_argument("--regenerate", action="store_true", help="solve with FEniCSx and rewrite the golden files")
    mode.add_argument("--overhead", action="store_true", help="time the bridge with a cold and a warm JIT cache")
    ap.add_argument("cases", nargs="*", choices=[[]] + list(BY_NAME), help="cases (default: all)")
    args = ap.parse_args(argv)
    cases = [BY_NAME[n] for n in args.cases] or list(CASES)
    if args.overhead:
        for k, v in overhead().items():
            print(f"{k:40s} {v:7.2f} s")
        return 0
    if args.check or args.regenerate:
        return _run_fenicsx(cases, args.regenerate)
    return _compare_scikit(cases)


if __name__ == "__main__":
    sys.exit(main())
