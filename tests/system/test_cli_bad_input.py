"""Bad input through the command line, in-process (``ctmrpim.cli.main``): exit status 2, one line naming
file, key and reason, no traceback, nothing written (README: "Bad input ends with one line naming the file,
key and reason"). The console script's own exit status is checked in test_cli.py.

Every case is a small variation of a valid 10 x 2 cantilever-like problem.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from ctmrpim.cli import main

BASE = """\
[problem]
name = "beam"

[parameters]
L = 10.0

[geometry]
add = [{ rectangle = [0, 0, "L", 2] }]

[nodes]
grid = [11, 3]

[material]
model = "linear-elastic"
E = 1000.0
nu = 0.3

[[constraint]]
where = "x == 0"
ux = "0"
uy = "0"

[[traction]]
where = "x == L"
ty = "-1"

[[probe]]
name = "tip"
at = ["L", 1]
"""
GRID_CSV = "x,y\n" + "\n".join(f"{x},{y}" for x in range(11) for y in (0, 1, 2)) + "\n"


def edit(old: str, new: str) -> str:
    assert BASE.count(old) == 1, old
    return BASE.replace(old, new)


@dataclass
class Case:
    toml: str | None                    # the problem file; None: no file is written
    expect: list[str]                   # the key and the reason, each must appear in the message
    args: list[str] = field(default_factory=list)   # extra arguments; "{file}" is the problem file
    files: dict[str, str] = field(default_factory=dict)
    target: str = "{file}"
    names_file: bool = True


CASES: dict[str, Case] = {
    "malformed-toml": Case(edit("E = 1000.0", "E = = 1000.0"), ["malformed TOML", "line 15"]),
    "unknown-section": Case(BASE + "\n[materials]\ndensity = 1\n",
                            ["unknown section [materials]", "did you mean 'material'?"]),
    "unknown-key-synonym": Case(edit("E = 1000.0", "youngs = 1000.0\nE = 1000.0"),
                                ["material.youngs", "unknown key", "did you mean 'E'?"]),
    "unknown-key-typo": Case(BASE + "\n[method]\nsupprt_radius = 4.0\n",
                             ["method.supprt_radius", "unknown key", "did you mean 'support_radius'?"]),
    "missing-name": Case(edit('name = "beam"\n', ""), ["problem.name", "missing required key"]),
    "missing-E": Case(edit("E = 1000.0\n", ""), ["material.E", "missing required key"]),
    "missing-geometry-add": Case(edit('add = [{ rectangle = [0, 0, "L", 2] }]\n', ""),
                                 ["geometry.add", "missing required key"]),
    "missing-where": Case(edit('where = "x == 0"\n', ""), ["constraint[0].where", "missing required key"]),
    "E-zero": Case(edit("E = 1000.0", "E = 0"), ["material.E", "must be > 0"]),
    "E-negative": Case(edit("E = 1000.0", 'E = "-L"'), ["material.E", "E = -10.0 must be > 0"]),
    "nu-half": Case(edit("nu = 0.3", "nu = 0.5"), ["material.nu", "nu = 0.5 must lie in (-1, 0.5)"]),
    "nu-below-minus-one": Case(edit("nu = 0.3", "nu = -1.2"), ["material.nu", "nu = -1.2 must lie in (-1, 0.5)"]),
    "empty-rectangle": Case(edit('[0, 0, "L", 2]', '["L", 0, 0, 2]'),
                            ["geometry.add[0]", "is empty (need x1 > x0 and y1 > y0)"]),
    "subtract-everything": Case(edit('}]\n\n[nodes]', '}]\nsubtract = [{ rectangle = [-1, -1, 11, 3] }]\n\n[nodes]'),
                                ["geometry", "empty after subtracting"]),
    "bow-tie": Case(edit('{ rectangle = [0, 0, "L", 2] }', "{ polygon = [[0, 0], [10, 2], [10, 0], [0, 2]] }"),
                    ["geometry.add[0]", "is not simple, it crosses or touches itself"]),
    "node-outside": Case(edit("grid = [11, 3]", 'file = "nodes.csv"'),
                         ["nodes", "lie outside the geometry", "(50, 50)"], files={"nodes.csv": GRID_CSV + "50,50\n"}),
    "node-file-not-numbers": Case(edit("grid = [11, 3]", 'file = "nodes.csv"'), ["nodes.file", "non-numbers"],
                                  files={"nodes.csv": GRID_CSV + "5,a\n"}),
    "constraint-selects-nothing": Case(edit('where = "x == 0"', 'where = "x == -1"'),
                                       ["constraint[0].where", "selects no boundary node"]),
    "traction-selects-nothing": Case(edit('where = "x == L"', 'where = "x == L/2"'),
                                     ["traction[0].where", "selects no boundary segment"]),
    "support-too-small": Case(BASE + "\n[method]\nsupport_radius = 0.5\n",
                              ["RPIM: point #", " at (", "linear basis needs at least 4", "method.support_radius"]),
    "eta-even": Case(BASE + "\n[method]\neta = 4.0\n", ["method.eta", "even integer"]),
    "unknown-name": Case(edit('uy = "0"', 'uy = "foo*x"'), ["constraint[0].uy", "unknown name 'foo'"]),
    "import": Case(edit('ux = "0"', """ux = "__import__('os').system('touch HACKED')\""""),
                   ["constraint[0].ux", "only these functions may be called", "__import__('os').system"]),
    "attribute": Case(edit('ty = "-1"', 'ty = "x.__class__"'), ["traction[0].ty", "Attribute is not allowed"]),
    "ufunc-out-argument": Case(edit('where = "x == 0"', 'where = "sin(x, y) == 0"'),
                               ["constraint[0].where", "sin takes 1 argument, not 2"]),
    "infinite-traction": Case(edit('ty = "-1"', 'ty = "9**9**9"'),
                              ["traction[0].ty", "'9**9**9' is inf at (10, "]),
    "probe-outside": Case(edit('at = ["L", 1]', 'at = ["2*L", 1]'),
                          ["probe[0].at", "(20, 1) lies outside the geometry"]),
    "gauss-points-bool": Case(BASE + "\n[method]\ngauss_points = true\n",
                              ["method.gauss_points", "must be an integer"]),
    "polynomial-list": Case(BASE + "\n[method]\npolynomial = []\n", ["method.polynomial", "must be one of"]),
    "name-with-slash": Case(edit('name = "beam"', 'name = "../beam"'), ["problem.name", "without / or"]),
    "detached-part": Case(edit('{ rectangle = [0, 0, "L", 2] }',
                               '{ rectangle = [0, 0, "L", 2] }, { rectangle = [20, 0, 30, 2] }'),
                          ["constraint", "part 2 of the body", "free to translate in x and y and to rotate"]),
    "unknown-benchmark": Case(None, ["'cantilevr' is neither a benchmark", "did you mean 'cantilever'?"],
                              target="cantilevr", names_file=False),
    "missing-file": Case(None, ["cannot read problem file (No such file or directory)"]),
    "set-without-value": Case(BASE, ["--set 'nodes.grid'", "expected section.key=value"], args=["--set", "nodes.grid"]),
    "set-bad-toml": Case(BASE, ["--set 'nodes.grid=[17,5'", "not valid TOML"], args=["--set", "nodes.grid=[17,5"]),
    "set-unknown-key": Case(BASE, ["method.etta", "did you mean 'eta'?"], args=["--set", "method.etta=5"]),
    "out-is-a-file": Case(BASE, ["--out", "cannot write the results"], files={"out": "not a folder"},
                          names_file=False),
}


@dataclass
class Outcome:
    code: int              # main's return value: the exit status
    stdout: str
    stderr: str
    folder: Path
    file: Path


def _run(case: Case, folder: Path, capsys, monkeypatch) -> Outcome:
    folder.mkdir()
    file = folder / "problem.toml"
    if case.toml is not None:
        file.write_text(case.toml)
    for fname, text in case.files.items():
        (folder / fname).write_text(text)
    args = ["run", case.target.format(file=file), "--out", str(folder / "out"),
            *(a.format(file=file) for a in case.args)]
    monkeypatch.chdir(folder)
    capsys.readouterr()
    code = main(args)
    out, err = capsys.readouterr()
    return Outcome(code, out, err, folder, file)


@pytest.mark.parametrize("name", list(CASES))
def test_bad_input(tmp_path: Path, capsys, monkeypatch, name: str) -> None:
    assert_refused(CASES[name], tmp_path / name, capsys, monkeypatch, name)


def assert_refused(case: Case, folder: Path, capsys, monkeypatch, name: str) -> None:
    """Run ``case`` in ``folder``: exit 2, one line naming the file, key and reason, nothing written."""
    out = _run(case, folder, capsys, monkeypatch)
    assert "Traceback" not in out.stdout + out.stderr, out.stderr
    assert out.code == 2, out.stdout + out.stderr
    assert out.stdout == ""
    lines = out.stderr.splitlines()
    assert len(lines) == 1, out.stderr
    line = lines[0]
    assert line.startswith("ctmrpim: error: "), line
    if case.names_file:
        assert line.startswith(f"ctmrpim: error: {out.file}: "), line
    for part in case.expect:
        assert part in line, f"{part!r} not in {line!r}"
    if name == "out-is-a-file":
        assert (out.folder / "out").read_text() == "not a folder"   # the user's file is left alone
    else:
        assert not (out.folder / "out").exists()
    assert not (out.folder / "HACKED").exists()


def test_eta_near_an_even_integer_warns_but_runs(tmp_path: Path, capsys, monkeypatch) -> None:
    out = _run(Case(BASE + "\n[method]\neta = 4.05\n", []), tmp_path / "case", capsys, monkeypatch)
    assert out.code == 0, out.stderr
    assert "Traceback" not in out.stdout + out.stderr
    lines = out.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("ctmrpim: warning: method.eta = 4.05 is close to the even integer 4")
    summary = json.loads((out.folder / "out" / "summary.json").read_text())
    assert summary["parameters"]["method"]["eta"] == 4.05
    assert (out.folder / "out" / "result.vtu").is_file()
