"""scikit-fem against the committed FEniCSx results (reference_fem/golden/, reference_fem/fenicsx_golden.py): the
same mesh, element and discrete problem solved by an independent code. Needs no dolfinx: these run everywhere."""
from __future__ import annotations

import numpy as np
import pytest
from verify import check

from reference_fem import fenicsx_golden as golden

REGENERATE = "python -m reference_fem.fenicsx_golden --regenerate"


@pytest.mark.parametrize("gc", golden.CASES, ids=lambda gc: gc.name)
def test_golden_file_is_on_the_current_mesh(gc: golden.GoldenCase) -> None:
    """The node generation still makes the mesh the golden result was computed on."""
    change = golden.mesh_change(gc, golden.read(gc))
    assert change is None, f"{change}: the golden file no longer matches; regenerate it with {REGENERATE}"


@pytest.mark.parametrize("gc", golden.CASES, ids=lambda gc: gc.name)
def test_scikit_fem_matches_fenicsx(gc: golden.GoldenCase, solutions) -> None:
    stored = golden.read(gc)
    assert stored["versions"]["dolfinx"].startswith("0.5.")
    diff = golden.differences(golden.record(solutions(gc.load(), method="fem", element=gc.element)), stored)
    kind = "linear" if gc.linear else "tip-load"
    check(f"fenicsx-{kind}-displacement", max(diff["u_nodes"], diff["u_probes"]))
    check(f"fenicsx-{kind}-energy", diff["energy"])
    if stored["probes"]:
        check(f"fenicsx-{kind}-stress", diff["stress_probes"])
    if "errors" in diff:
        check("fenicsx-linear-errors", diff["errors"])


def test_every_linear_benchmark_and_a_user_file_is_covered() -> None:
    targets = {gc.target for gc in golden.CASES}
    assert {"cantilever", "plate-hole", "self-weight", "manufactured", "patch", "tip-load"} <= targets
    assert any(t.endswith(".toml") for t in targets)
    elements = {gc.element for gc in golden.CASES}
    assert {"q1", "p1", "p2"} <= elements


def test_richardson_recovers_a_known_limit() -> None:
    from reference_fem.fenicsx_converged import richardson
    h = [0.4, 0.2, 0.1, 0.05]
    r = richardson(h, [2.0 + 0.3 * x ** 1.5 for x in h])
    assert abs(r["order"] - 1.5) < 1e-12 and abs(r["value"] - 2.0) < 1e-12 and r["error"] > 0
    assert np.isnan(richardson(h, [1.0, 2.0, 1.5, 1.7])["value"])     # oscillating: not asymptotic


def test_converged_values() -> None:
    """The committed converged FEniCSx values (python -m reference_fem.fenicsx_converged): the plate's stress
    concentration within 1 % of 3 on the finest mesh; P2 and P3 extrapolate to the same value, each with a
    small estimated error."""
    import json

    from reference_fem.fenicsx_converged import OUT
    data = json.loads(OUT.read_text())
    check("fenicsx-plate-hole-scf", abs(data["plate-hole"]["series"][-1]["scf"] / 3.0 - 1.0))
    for label, (p2, p3) in data["series"].items():
        for key in ("ux", "uy"):
            if key in p2:
                a, b = p2[key]["richardson"], p3[key]["richardson"]
                check("fenicsx-converged-p2-p3", abs(a["value"] / b["value"] - 1.0))
                check("fenicsx-converged-error", max(a["error"] / abs(a["value"]), b["error"] / abs(b["value"])))
