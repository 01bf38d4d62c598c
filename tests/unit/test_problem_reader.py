"""Reading problem files (ctmrpim.problem.reader): the cantilever benchmark, --set overrides, defaults applied and
recorded, parameters in order, nodes from a CSV file."""
from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.problem.node_cloud import NodeSpec, make_nodes
from ctmrpim.problem.reader import apply_overrides, read_case
from ctmrpim.problem.settings import Method

MINIMAL = """
[problem]
name = "plate"

[geometry]
add = [{ rectangle = [0, 0, 10, 2] }]

[nodes]
grid = [11, 3]

[material]
model = "linear-elastic"
E = 1000.0
nu = 0.25

[[constraint]]
where = "x == 0"
ux = "0"
"""


def write(tmp_path: Path, text: str, name: str = "p.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_cantilever_benchmark() -> None:
    case = benchmarks.load("cantilever")
    p = case.problem
    assert p.name == "cantilever" and p.analysis == "linear" and p.plane == "stress" and p.thickness == 1.0
    assert p.parameters == {"P": -1000.0, "E": 3.0e7, "nu": 0.3, "L": 48.0, "W": 12.0, "I": 144.0}
    assert (p.material.E, p.material.nu, p.material.density) == (3.0e7, 0.3, 0.0)
    assert p.geometry.bounds == (0.0, -6.0, 48.0, 6.0) and p.geometry.is_rectangle()
    assert p.geometry.area == 576.0
    assert case.nodes == NodeSpec(grid=(33, 9))
    assert case.method == Method(support_radius=4.0, eta=5.0, polynomial="linear", line_spacing=(1 / 3, 1 / 3),
                                 gauss_points=1, alpha=1.5, integration="ctm-vci")
    assert [(q.name, q.x, q.y) for q in p.probes] == [("tip", 48.0, 0.0), ("root_top", 0.0, 6.0)]
    assert len(p.constraints) == 1 and len(p.tractions) == 1 and not p.pressures
    # the traction is the exact parabolic shear, the constraint the exact displacement (Eq. 35)
    y = np.linspace(-6, 6, 7)
    np.testing.assert_allclose(p.tractions[0].ty(np.full(7, 48.0), y), -1000 / 288 * (36 - y**2), rtol=1e-14)
    np.testing.assert_allclose(p.constraints[0].uy(np.zeros(7), y), p.exact.uy(np.zeros(7), y), rtol=0, atol=0)
    assert p.constraints[0].where(np.array([0.0, 0.01, 1.0]), np.zeros(3), eq_tol=0.02).tolist() == [True, True, False]
    assert case.resolved["parameters"]["I"] == 144.0
    assert case.resolved["geometry"] == {"add": [{"rectangle": [0.0, -6.0, 48.0, 6.0]}], "subtract": []}
    assert case.resolved["method"]["line_spacing"] == [1 / 3, 1 / 3]


def test_overrides() -> None:
    raw = tomllib.loads(benchmarks.path("cantilever").read_text())
    new = apply_overrides(raw, ["nodes.grid=[65, 17]", "method.eta=5.5", "method.polynomial=quadratic",
                                "parameters.P=-2000", 'problem.plane="strain"'])
    assert raw["nodes"] == {"grid": [33, 9]} and raw["method"]["eta"] == 5.0   # the input is not touched
    assert new["nodes"] == {"grid": [65, 17]}
    assert new["method"]["eta"] == 5.5 and new["method"]["polynomial"] == "quadratic"
    assert new["parameters"]["P"] == -2000 and new["problem"]["plane"] == "strain"
    # grid, spacing and file exclude each other: a new one replaces the old
    assert apply_overrides(raw, ["nodes.spacing=2.0"])["nodes"] == {"spacing": 2.0}
    assert apply_overrides({"nodes": {"spacing": 1.0}}, ["nodes.grid=[17,5]"])["nodes"] == {"grid": [17, 5]}

    case = benchmarks.load("cantilever", ["nodes.grid=[17,5]", "parameters.P=-2000", "method.eta=5.5"])
    assert case.nodes == NodeSpec(grid=(17, 5)) and case.method.eta == 5.5
    # parameters are evaluated after the override: I depends on W, the traction on P
    assert case.problem.parameters["P"] == -2000.0
    assert case.problem.tractions[0].ty(np.array([48.0]), np.array([0.0]))[0] == pytest.approx(-2000 / 288 * 36)
    spaced = benchmarks.load("cantilever", ["nodes.spacing=3"])
    assert spaced.nodes == NodeSpec(spacing=3.0) and spaced.resolved["nodes"] == {"spacing": 3.0}


@pytest.mark.parametrize("item, match", [
    ("nodes.grid", "expected section.key=value"),
    ("grid=[17,5]", "expected section.key=value"),
    ("method.=3", "expected section.key=value"),
    (".eta=3", "expected section.key=value"),
    ("constraint.where=1", "can set keys of"),
    ("foo.bar=1", "can set keys of"),
    ("nodes.grid=[17,5", "not valid TOML"),
    ("parameters.h=0.5", r"no parameter 'h' \(its parameters: P, E, nu, L, W, I\)"),   # would define one nothing uses
])
def test_bad_overrides(item: str, match: str) -> None:
    with pytest.raises(ProblemError, match=match) as info:
        benchmarks.load("cantilever", [item])
    assert info.value.source.endswith("cantilever.toml")


def test_override_unknown_key_suggests() -> None:
    with pytest.raises(ProblemError, match=r"did you mean 'support_radius'\?") as info:
        benchmarks.load("cantilever", ["method.supprt_radius=3"])
    assert info.value.key == "method.supprt_radius"


def test_defaults_are_recorded(tmp_path: Path) -> None:
    case = read_case(write(tmp_path, MINIMAL))
    assert set(case.defaults) == {
        "problem.analysis = 'linear'", "problem.plane = 'stress'", "problem.thickness = 1.0",
        "problem.gravity = [0.0, 0.0]", "material.density = 0.0",
        *(f"method.{k} = {v.default!r}" for k, v in Method.__dataclass_fields__.items() if k != "integration"),
        "method.integration = 'ctm-vci'"}          # the default of a linear analysis
    assert case.method == Method(integration="ctm-vci")
    assert case.resolved["problem"] == {"name": "plate", "analysis": "linear", "plane": "stress", "thickness": 1.0,
                                        "gravity": [0.0, 0.0]}
    assert case.resolved["material"]["density"] == 0.0
    given = read_case(write(tmp_path, MINIMAL + "\n[method]\neta = 3.0\n"))
    assert "method.eta = 5.0" not in given.defaults and given.method.eta == 3.0


def test_parameters_are_evaluated_in_order(tmp_path: Path) -> None:
    text = MINIMAL.replace("[geometry]", '[parameters]\na = 2\nb = "3*a"\nc = "hypot(a, b) - sqrt(40)"\n\n[geometry]')
    text = text.replace("rectangle = [0, 0, 10, 2]", 'rectangle = [0, 0, "b + 4", "a"]')
    case = read_case(write(tmp_path, text))
    assert case.problem.parameters == {"a": 2.0, "b": 6.0, "c": pytest.approx(0.0, abs=1e-14)}
    assert case.problem.geometry.bounds == (0.0, 0.0, 10.0, 2.0)


# -- geometry -----------------------------------------------------------------------------------------


# -- nodes ----------------------------------------------------------------------------------------------


def test_nodes_from_csv(tmp_path: Path) -> None:
    X, Y = np.meshgrid(np.linspace(0, 10, 6), np.linspace(0, 2, 3))
    rows = "\n".join(f"{float(x)!r}, {float(y)!r}" for x, y in zip(X.ravel(), Y.ravel()))
    (tmp_path / "cloud.csv").write_text("x, y\n" + rows)
    text = MINIMAL.replace("grid = [11, 3]", 'file = "cloud.csv"')
    case = read_case(write(tmp_path, text))      # the CSV path is relative to the problem file
    assert case.nodes == NodeSpec(file="cloud.csv") and case.base_dir == tmp_path
    nodes = make_nodes(case.problem.geometry, case.nodes, case.base_dir)
    np.testing.assert_array_equal(nodes, np.c_[X.ravel(), Y.ravel()])


@pytest.mark.parametrize("content, match", [
    ("x,y\n0,0\n1,a\n2,2\n", "holds non-numbers, first in data row 2"),
    ("a,b\n0,0\n1,1\n2,2\n", "needs columns x and y"),
    ("x,y\n0,0\n1,1\n", "holds 2 node"),
    ("", "cannot read node file"),
])
def test_bad_csv(tmp_path: Path, content: str, match: str) -> None:
    (tmp_path / "cloud.csv").write_text(content)
    case = read_case(write(tmp_path, MINIMAL.replace("grid = [11, 3]", 'file = "cloud.csv"')))
    with pytest.raises(ProblemError, match=match) as info:
        make_nodes(case.problem.geometry, case.nodes, case.base_dir)
    assert info.value.key == "nodes.file"
