"""Converged finite-element values from FEniCSx where no exact solution exists: P2 and P3 on meshes refined by
halving h, with Richardson extrapolation over the three finest and its estimated error.

    python -m reference_fem.fenicsx_converged        solve (dolfinx needed), print, write golden/converged.json

- the fully clamped cantilever (``golden/cantilever-clamped.toml``: the benchmark with ux = uy = 0 at x = 0):
  tip deflection;
- the tip-load of a continuum beam (benchmark ``tip-load``, neo-Hookean, lambda = 3.6): tip displacements;
- the plate with a hole: the stress concentration sxx / T at the hole's top from P2 (exact: 3), spacings
  0.25, 0.125, 0.0625.

``converged.json`` keeps each series (h, values) and the extrapolation, so that a comparison can use the
converged values on a machine without dolfinx.
"""
from __future__ import annotations

import json
import math
import sys
import time

from ctmrpim.cases import load_case
from ctmrpim.methods import solve
from reference_fem.fenicsx_golden import FOLDER

OUT = FOLDER / "converged.json"
CLAMPED = str(FOLDER / "cantilever-clamped.toml")
#: (label, target, [overrides per mesh], h per mesh, quantities read from the tip probe)
SERIES = (
    ("cantilever-clamped", CLAMPED, [[f"nodes.grid=[{32 * k + 1}, {8 * k + 1}]"] for k in (1, 2, 4, 8)],
     [1.5 / k for k in (1, 2, 4, 8)], ("uy",)),
    ("tip-load", "tip-load", [[f"nodes.grid=[{50 * k + 1}, {5 * k + 1}]"] for k in (1, 2, 4)],
     [0.2 / k for k in (1, 2, 4)], ("ux", "uy")),
)
PLATE_SPACINGS = (0.25, 0.125, 0.0625)


def richardson(h: list[float], values: list[float]) -> dict[str, float]:
    """Extrapolation to h = 0 over the last three values (h halving): the observed order p, the extrapolated
    value and its estimated error |extrapolated - finest|; NaN where the differences do not shrink monotonically
    (not yet in the asymptotic range)."""
    f1, f2, f3 = values[-3:]
    ratio = h[-2] / h[-1]
    d1, d2 = f2 - f1, f3 - f2
    if d1 == 0 or d2 == 0 or d1 * d2 < 0 or abs(d2) >= abs(d1):
        return {"order": math.nan, "value": math.nan, "error": math.nan}
    p = math.log(d1 / d2) / math.log(ratio)
    value = f3 + d2 / (ratio ** p - 1.0)
    return {"order": p, "value": value, "error": abs(value - f3)}


def run_series(label: str, target: str, meshes: list[list[str]], h: list[float], keys: tuple[str, ...],
               element: str) -> dict:
    """One quantity series of ``target`` solved by FEniCSx ``element`` on each mesh, with its extrapolation."""
    values: dict[str, list[float]] = {k: [] for k in keys}
    seconds = []
    for overrides in meshes:
        start = time.perf_counter()
        result = solve(load_case(target, overrides), "fenicsx", element)
        seconds.append(round(time.perf_counter() - start, 1))
        for k in keys:
            values[k].append(result.probes["tip"][k])
        print(f"{label} {element} {overrides[0]}: " + ", ".join(f"{k} {values[k][-1]:.10g}" for k in keys)
              + f" ({seconds[-1]} s)", flush=True)
    return {"element": element, "h": h, "meshes": [m[0] for m in meshes], "seconds": seconds,
            **{k: {"values": v, "richardson": richardson(h, v)} for k, v in values.items()}}


def plate_hole() -> dict:
    """sxx / T at the hole's top from FEniCSx P2 on each spacing."""
    out = []
    for s in PLATE_SPACINGS:
        case = load_case("plate-hole", [f"nodes.spacing={s}"])
        result = solve(case, "fenicsx", "p2")
        scf = result.probes["hole_top"]["sxx"] / case.problem.parameters["T"]
        out.append({"spacing": s, "nodes": result.counts["nodes"], "scf": scf})
        print(f"plate-hole p2 spacing {s}: sxx/T = {scf:.6f} ({100 * abs(scf / 3 - 1):.3f} % from 3)", flush=True)
    return {"element": "p2", "series": out}


def main() -> int:
    """Solve every series, print them with their extrapolations and write ``converged.json``."""
    start = time.perf_counter()
    content: dict = {"series": {}}
    for label, target, meshes, h, keys in SERIES:
        content["series"][label] = [run_series(label, target, meshes, h, keys, e) for e in ("p2", "p3")]
        for s in content["series"][label]:
            for k in keys:
                r = s[k]["richardson"]
                print(f"  {label} {s['element']} {k}: converged {r['value']:.10g} +- {r['error']:.2g} "
                      f"(observed order {r['order']:.2f})")
    content["plate-hole"] = plate_hole()
    content["seconds"] = round(time.perf_counter() - start, 1)
    OUT.write_text(json.dumps(content, indent=1) + "\n")
    print(f"wrote {OUT} ({content['seconds']} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
