"""The analysis settings of a problem file (ctmrpim.problem.settings and the reader): each inconsistent or
out-of-range value is refused naming its key."""
from __future__ import annotations

from pathlib import Path

import pytest

from ctmrpim import benchmarks
from ctmrpim.cases import load_case
from ctmrpim.errors import ProblemError

BLOCK = Path(__file__).parents[1] / "data" / "mc_block.toml"


@pytest.mark.parametrize("change, key", [
    (["strength-reduction.step=0"], "strength-reduction.step"),
    (["strength-reduction.width=0.5"], "strength-reduction.width"),
    (['strength-reduction.solver="dynamic"'], "strength-reduction.solver"),
    (["strength-reduction.values=1.2"], "strength-reduction.values"),
    (['problem.analysis="quasi-static"'], "problem.analysis"),
    (['loading.tangent="secant"'], "loading.tangent"),
])
def test_bad_strength_reduction_input_names_the_key(change, key: str) -> None:
    with pytest.raises(ProblemError, match=key.replace(".", r"\.")):
        benchmarks.load("slope", change)


def test_until_failure_needs_a_mohr_coulomb_quasi_static_analysis() -> None:
    with pytest.raises(ProblemError, match="until_failure"):
        benchmarks.load("tip-load", ["loading.until_failure=true"])


def test_dynamic_section_needs_a_relaxation_analysis() -> None:
    with pytest.raises(ProblemError, match="dynamic"):
        benchmarks.load("slope", ["dynamic.steps=100"])


@pytest.mark.parametrize("setting, key", [
    ("explicit.dt=-1", "explicit.dt"), ("explicit.cfl=2", "explicit.cfl"), ("explicit.damping=1", "explicit.damping"),
    ("explicit.rebuild_strain=0", "explicit.rebuild_strain"), ("explicit.detached=\"drop\"", "explicit.detached"),
    ("explicit.initial=\"k0\"", "explicit.initial"), ("explicit.checkpoint_every=1.5", "explicit.checkpoint_every"),
])
def test_bad_explicit_settings(setting, key):
    with pytest.raises(ProblemError) as err:
        benchmarks.load("column-collapse", [setting])
    assert key in err.value.message


def test_walls_need_explicit_dynamics(tmp_path):
    text = benchmarks.path("column-collapse").read_text().replace('analysis = "explicit"', 'analysis = "linear"')
    text = text.replace('model = "mohr-coulomb"', 'model = "linear-elastic"')
    f = tmp_path / "p.toml"
    f.write_text(text)
    from ctmrpim.problem.reader import read_case
    with pytest.raises(ProblemError, match="explicit"):
        read_case(f)


@pytest.mark.parametrize("overrides, message", [
    (['material.model="linear-elastic"', 'method.formulation="total-lagrangian"'], "needs model = 'neo-hookean'"),
    (['problem.analysis="linear"'], "needs model = 'linear-elastic'"),
    (["loading.steps=0"], "loading.steps"),
])
def test_inconsistent_analysis_and_material_are_errors(overrides, message: str) -> None:
    with pytest.raises(ProblemError, match=message):
        benchmarks.load("tip-load", overrides)


@pytest.mark.parametrize("change, message", [
    (lambda t: t.replace("phi = \"phi\"\n", ""), "needs phi"),
    (lambda t: t.replace('plane = "strain"', 'plane = "stress"'), "plane strain"),
    (lambda t: t.replace("psi = 0.0", "psi = 40.0"), "material.psi"),
])
def test_bad_mohr_coulomb_input_names_the_key(tmp_path, change, message: str) -> None:
    from ctmrpim.errors import ProblemError

    path = tmp_path / "block.toml"
    path.write_text(change(BLOCK.read_text()))
    with pytest.raises(ProblemError, match=message):
        load_case(str(path), [])


@pytest.mark.parametrize("target, change", [
    ("cantilever", ['method.integration="vci"']),
    ("cantilever", ['method.correction="cubic"']),
])
def test_bad_integration_settings_name_the_key(target: str, change: list[str]) -> None:
    with pytest.raises(ProblemError, match=r"method\.(integration|correction)"):
        benchmarks.load(target, change)


@pytest.mark.parametrize("target, change", [
    ("tip-load", ['method.integration="cell-gauss"']),                              # comparators: linear only
    ("column-collapse", ['method.integration="ctm-vci"']),                          # explicit: momentum drifts
    ("cantilever", ['method.integration="ctm-vci"', 'method.boundary="geometry"']),  # not on the node loops
])
def test_consistent_integration_is_refused_where_it_is_not_implemented(target: str, change: list[str]) -> None:
    import ctmrpim

    with pytest.raises(ProblemError, match=r"method\.integration"):
        ctmrpim.solve(benchmarks.load(target, change))


def test_range_errors_give_the_range() -> None:
    from ctmrpim.errors import ProblemError
    from ctmrpim.materials.mohr_coulomb import MohrCoulomb
    from ctmrpim.problem.settings import Loading

    with pytest.raises(ProblemError, match=r"material.phi: 95.0 is out of range: it must be in \[0, 90\) degrees"):
        MohrCoulomb(1e7, 0.3, 10.0, 95.0)
    with pytest.raises(ProblemError, match=r"material.psi: 40.0 is out of range: it must be in \[0, phi\] = \[0, 30\]"):
        MohrCoulomb(1e7, 0.3, 10.0, 30.0, 40.0)
    with pytest.raises(ProblemError, match=r"loading.steps: 0 must be an integer >= 1"):
        Loading(steps=0)
