"""The equivalent plastic strain written at the nodes is never negative and never exceeds its largest value at
the integration points (docs/design.md, 'Output'): checked on the footing (CTM-RPIM and P2) and the column
collapse, where the L2 projection it replaced overshoots."""
from __future__ import annotations

import tempfile

import numpy as np
import pytest
from clouds import QUICK_COLUMN

import ctmrpim
from ctmrpim.materials.mohr_coulomb import equivalent_plastic_strain
from ctmrpim.solvers import plastic_analysis
from ctmrpim.solvers.explicit import output

#: the footing below Prandtl's load on a coarse grid: yielding under the footing's edge, one second's solve
FOOTING = ["parameters.nx=25", "parameters.ny=11", "parameters.q_max=450e3", "loading.steps=3",
           "loading.until_failure=false"]


@pytest.fixture
def spied(monkeypatch):
    """Records, at every nodal output of a quasi-static Mohr-Coulomb run, the largest point value, the nodal
    field written and the L2 projection of the same point values."""
    seen: list[tuple[float, np.ndarray, np.ndarray]] = []
    original = plastic_analysis.PlasticOutput.plastic_field

    def plastic_field(self, plastic_strain):
        out = original(self, plastic_strain)
        eq = equivalent_plastic_strain(plastic_strain)
        seen.append((float(eq.max()), out["plastic_strain"], self.nodal(eq[:, None])[:, 0]))
        return out
    monkeypatch.setattr(plastic_analysis.PlasticOutput, "plastic_field", plastic_field)
    return seen


@pytest.mark.parametrize("method", ["ctm-rpim", "fem"])
def test_footing_plastic_strain_is_in_range(method: str, spied) -> None:
    r = ctmrpim.solve(ctmrpim.load_case("footing", FOOTING), method)
    assert len(spied) == len(r.series) + 1 and r.fields["plastic_strain"].max() > 0
    for top, nodal, _ in spied:
        assert nodal.min() >= 0.0 and nodal.max() <= top
    assert all(np.array_equal(s["fields"]["plastic_strain"], n) for s, (_, n, _) in zip(r.series, spied))
    if method == "ctm-rpim":   # what it replaced: the L2 projection onto the nodes went below zero
        assert min(p.min() for _, _, p in spied) < 0.0


def test_column_collapse_plastic_strain_is_in_range(monkeypatch) -> None:
    """Every saved state of a short collapse: the nodal field within [0, the largest point value]."""
    seen: list[tuple[float, np.ndarray]] = []
    original = output.SeriesOutput.nodal_fields

    def nodal_fields(self):
        out = original(self)
        eq = equivalent_plastic_strain(self.plastic)
        seen.append((float(eq[self.frame.w > 0].max()), out["plastic_strain"]))   # the points that integrate
        return out
    monkeypatch.setattr(output.SeriesOutput, "nodal_fields", nodal_fields)
    case = ctmrpim.load_case("column-collapse", [*QUICK_COLUMN, "explicit.duration=0.1", "explicit.save_every=0.05"])
    with tempfile.TemporaryDirectory() as out:
        r = ctmrpim.solve(case, out=out)
    assert len(seen) >= 3 and max(top for top, _ in seen) > 0
    for top, nodal in seen:
        assert nodal.min() >= 0.0 and nodal.max() <= top
    np.testing.assert_array_equal(r.fields["plastic_strain"], seen[-1][1])
