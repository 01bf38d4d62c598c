"""Input that passes the file's validation but would give a wrong or arbitrary answer with exit status 0:
too few supports, conflicting constraints, settings without effect, undecodable files and sizes that
cannot fit. Each is refused like bad input (exit 2, one line, nothing written), for CTM-RPIM and for the
finite elements (the same Problem), or warned about where it is harmless."""
from __future__ import annotations

import json
from pathlib import Path

import pytest
from test_cli_bad_input import BASE, Case, _run, assert_refused, edit

FE = ["--solver", "fem", "--element"]
#: the 10 x 2 beam held only by one pin, and only by ux on its end
PINNED = edit('where = "x == 0"', 'where = "x == 0 and y == 0"')
ROLLER = edit('ux = "0"\nuy = "0"', 'ux = "0"')

CASES = {
    "one-pin": Case(PINNED, ["constraint", "free to rotate about (0, 0)"]),
    "one-pin-q1": Case(PINNED, ["constraint", "free to rotate about (0, 0)"], args=FE + ["q1"]),
    "one-pin-p2": Case(PINNED, ["constraint", "free to rotate about (0, 0)"], args=FE + ["p2"]),
    "roller-only": Case(ROLLER, ["constraint", "free to translate in y"]),
    "roller-only-p1": Case(ROLLER, ["constraint", "free to translate in y"], args=FE + ["p1"]),
    "conflicting-edge": Case(BASE + '[[constraint]]\nwhere = "x == 0"\nux = "0.01"\n',
                             ["constraint[1]", "ux = 0.01 at (0, 0)", "constraint[0] prescribes ux = 0", "disagree"]),
    "conflicting-corner": Case(BASE + '[[constraint]]\nwhere = "y == 0"\nuy = "0.01"\n',
                               ["constraint[1]", "uy = 0.01 at (0, 0)", "disagree"]),
    "conflicting-corner-p2": Case(BASE + '[[constraint]]\nwhere = "y == 0"\nuy = "0.01"\n',
                                  ["constraint[1]", "uy = 0.01 at (0, 0)", "disagree"], args=FE + ["p2"]),
    "traction-on-support": Case(BASE + '[[traction]]\nwhere = "x == 0"\ntx = "5"\n',
                                ["traction[1]", "tx acts only where a constraint prescribes", "no effect"]),
    "gravity-without-density": Case(edit('name = "beam"', 'name = "beam"\ngravity = [0, -9.81]'),
                                    ["material.density", "no effect with material.density = 0"]),
    "loading-in-linear": Case(BASE + "[loading]\nsteps = 5\n", ["loading", "no effect in a 'linear' analysis"]),
    "cohesion-elastic": Case(edit("nu = 0.3", "nu = 0.3\nc = 10"), ["material.c", "only by model = \"mohr-coulomb\""]),
    "parameter-pi": Case(edit("L = 10.0", "L = 10.0\npi = 3"), ["parameters.pi", "would replace the constant pi"]),
    "parameter-sin": Case(edit("L = 10.0", "L = 10.0\nsin = 3"), ["parameters.sin", "would replace the function sin()"]),
    "exact-incomplete": Case(BASE + '[exact]\nux = "0"\n', ["exact", "uy missing"]),
    "formulation-in-linear": Case(BASE + '[method]\nformulation = "total-lagrangian"\n',
                                  ["method.formulation", "read only by a quasi-static analysis"]),
    "correction-with-ctm": Case(BASE + '[method]\nintegration = "ctm"\ncorrection = "linear"\n',
                                ["method.correction", "read only by integration = \"ctm-vci\""]),
    "min-support-static": Case(BASE + "[method]\nmin_support = 12\n", ["method.min_support", "explicit dynamics"]),
    "empty-out": Case(BASE, ["--out", "names no folder"], args=["--out", ""], names_file=False),
    # typed for this run: refused; the same keys in the file only get a warning (test_fem_warns_...)
    "method-key-set-for-fem": Case(BASE, ["--set: method.eta has no effect on the finite-element solve",
                                          "reads only method.match_tolerance of [method]", "remove --set method.eta"],
                                   args=["--set", "method.eta=3"] + FE + ["q1"]),
    "method-keys-set-for-fem": Case(BASE, ["--set: method.alpha, method.line_spacing have no effect",
                                           "remove those --set"],
                                    args=["--set", "method.alpha=2", "--set", "method.line_spacing=[0.5, 0.5]",
                                          "--solver", "fem"]),
    "huge-grid": Case(edit("grid = [11, 3]", "grid = [100000, 100000]"),
                      ["nodes", "too large for this machine", "1e+10 nodes", "GiB of memory"]),
    "tiny-spacing": Case(edit("grid = [11, 3]", "spacing = 1e-5"), ["nodes", "too large for this machine"]),
    "tiny-line-spacing": Case(BASE + "[method]\nline_spacing = [1e-4, 1e-4]\n",
                              ["method.line_spacing", "too large for this machine", "integration points"]),
}


@pytest.mark.parametrize("name", list(CASES))
def test_refused(tmp_path: Path, capsys, monkeypatch, name: str) -> None:
    assert_refused(CASES[name], tmp_path / name, capsys, monkeypatch, name)


@pytest.mark.parametrize("encoding", ["latin-1", "utf-16"])
def test_undecodable_problem_file(tmp_path: Path, capsys, monkeypatch, encoding: str) -> None:
    file = tmp_path / "problem.toml"
    file.write_bytes(edit('name = "beam"', 'name = "beam"\ndescription = "café"').encode(encoding))
    out = _run(Case(None, [], target=str(file)), tmp_path / "case", capsys, monkeypatch)
    assert out.code == 2 and "Traceback" not in out.stderr
    assert out.stderr.count("\n") == 1 and "not UTF-8 text" in out.stderr and "save it as UTF-8" in out.stderr
    assert not (out.folder / "out").exists()


def test_density_without_gravity_warns_and_runs(tmp_path: Path, capsys, monkeypatch) -> None:
    out = _run(Case(edit("nu = 0.3", "nu = 0.3\ndensity = 2000"), []), tmp_path / "case", capsys, monkeypatch)
    assert out.code == 0, out.stderr
    lines = out.stderr.splitlines()
    assert lines == ["ctmrpim: warning: material.density = 2000 has no effect in a linear analysis without "
                     "problem.gravity"]
    summary = json.loads((out.folder / "out" / "summary.json").read_text())
    assert summary["parameters"]["material"]["density"] == 2000
    assert summary["notes"] == [lines[0].removeprefix("ctmrpim: warning: ")]    # what was printed is kept


def test_fem_warns_about_the_files_method_keys_and_notes_them(tmp_path: Path, capsys, monkeypatch) -> None:
    """CTM-RPIM's [method] keys in the file (every benchmark has some) under --solver fem: one warning line
    naming them, the run goes on, and the summary's notes say the same; match_tolerance, which the finite
    elements read, is not named, and setting it with --set is accepted."""
    toml = BASE + "[method]\neta = 3.0\nalpha = 2.0\nmatch_tolerance = 0.02\n"
    out = _run(Case(toml, [], args=FE + ["q1", "--set", "method.match_tolerance=0.03"]), tmp_path / "case", capsys,
               monkeypatch)
    assert out.code == 0, out.stderr
    warning = ("[method] eta, alpha have no effect on the finite-element solve (--solver fem reads only "
               "method.match_tolerance of [method])")
    assert out.stderr.splitlines() == [f"ctmrpim: warning: {warning}"]
    summary = json.loads((out.folder / "out" / "summary.json").read_text())
    assert summary["notes"] == [warning] and summary["method"] == "fem-q1"


def test_ctm_rpim_reads_the_method_keys_and_says_nothing(tmp_path: Path, capsys, monkeypatch) -> None:
    out = _run(Case(BASE + "[method]\neta = 3.0\n", [], args=["--set", "method.alpha=2"]), tmp_path / "case",
               capsys, monkeypatch)
    assert out.code == 0 and out.stderr == "", out.stderr
    assert "notes" not in json.loads((out.folder / "out" / "summary.json").read_text())
