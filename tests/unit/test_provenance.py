"""Provenance of full-mode results (issue 22, item 7): a sidecar records the code that made a study's table and
figure; a changed numerics source makes it stale, a rewritten file modified; the committed ones are stamped."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from studies import provenance

ROOT = Path(__file__).resolve().parents[2]


#: a study with quick and full cases listed from one table of grids
DEMO = """from studies.helper import z
from studies.sweep import CaseSpec
GRIDS = {"quick": [1], "full": [2, 3]}


def specs(quick):
    return [CaseSpec("beam", (f"n={n}",)) for n in GRIDS["quick" if quick else "full"]]
"""
SWEEP = """from dataclasses import dataclass


@dataclass(frozen=True)
class CaseSpec:
    target: str
    overrides: tuple = ()
    solver: str = "ctm-rpim"
    element: object = None
    labels: tuple = ()
"""


def _tree(root: Path) -> None:
    """A miniature repository: the numerics packages, a study that imports a helper, and non-numerics modules."""
    for rel, text in {"ctmrpim/solver.py": "x = 1\n", "ctmrpim/cli.py": "help = 'a'\n",
                      "ctmrpim/benchmarks/beam.toml": "L = 1\n", "reference_fem/fem.py": "y = 2\n",
                      "studies/demo.py": DEMO, "studies/__init__.py": "",
                      "studies/helper.py": "z = 3\n", "studies/sweep.py": SWEEP,
                      "studies/other.py": "w = 4\n"}.items():
        (root / rel).parent.mkdir(parents=True, exist_ok=True)
        (root / rel).write_text(text)


@pytest.fixture
def made(tmp_path: Path) -> tuple[Path, Path]:
    root, out = tmp_path / "repo", tmp_path / "full"
    _tree(root)
    out.mkdir()
    (out / "demo.csv").write_text("a,b\n1,2\n")
    (out / "demo.png").write_bytes(b"\x89PNG fake")
    provenance.stamp(out, "demo", root=root)
    return root, out


def test_the_numerics_sources_of_a_study(tmp_path: Path) -> None:
    _tree(tmp_path)
    files = provenance.numerics_files("demo", tmp_path)
    assert "ctmrpim/solver.py" in files and "ctmrpim/benchmarks/beam.toml" in files
    assert "reference_fem/fem.py" in files and {"studies/demo.py", "studies/helper.py"} <= set(files)
    # the command line, the sweep executor and other studies compute nothing this study's numbers depend on
    assert not {"ctmrpim/cli.py", "studies/sweep.py", "studies/other.py"} & set(files)


def test_a_fresh_stamp_is_current(made) -> None:
    root, out = made
    record = json.loads(provenance.sidecar(out, "demo").read_text())
    assert set(record["files"]) == {"demo.csv", "demo.png"} and record["mode"] == "full"
    assert record["git_commit"] is None   # the miniature tree is no git repository
    assert provenance.status(out, "demo", root).state == "current"


def test_a_changed_source_makes_it_stale(made) -> None:
    root, out = made
    (root / "studies/sweep.py").write_text(SWEEP + "\nDASK = None\n")   # not a numerics source
    (root / "ctmrpim/cli.py").write_text("help = 'b'\n")
    assert provenance.status(out, "demo", root).state == "current"
    (root / "studies/helper.py").write_text("z = 4\n")
    (root / "ctmrpim/new.py").write_text("")
    s = provenance.status(out, "demo", root)
    assert s.state == "stale" and s.changed == ["ctmrpim/new.py", "studies/helper.py"]
    assert "studies/helper.py" in s.describe() and "2 numerics sources changed" in s.describe()
    assert "2 numerics" not in s.describe(count=False)


def test_docstrings_comments_and_drawing_do_not_make_it_stale(made) -> None:
    """Only an edit that can change a number counts: a docstring, a comment, a blank line or the study's figure
    function leaves the result current; a redrawn figure is recorded and stays current."""
    root, out = made
    (root / "ctmrpim/solver.py").write_text('"""The solver."""\n\n# why x is one\nx = 1   # one\n')
    (root / "studies/demo.py").write_text((root / "studies/demo.py").read_text()
                                          + "\n\ndef figure(df):\n    return df.plot().figure\n")
    assert provenance.status(out, "demo", root).state == "current"
    (root / "ctmrpim/solver.py").write_text('"""The solver."""\nx = 2\n')
    assert provenance.status(out, "demo", root).state == "stale"


def test_quick_cases_do_not_make_it_stale_and_full_ones_do(made) -> None:
    """The study module's case listing is hashed as the full run's case list: another quick grid leaves the full
    result current, another full grid makes it stale and names the case list."""
    root, out = made
    demo = root / "studies/demo.py"
    demo.write_text(DEMO.replace('"quick": [1]', '"quick": [1, 5]'))
    assert provenance.status(out, "demo", root).state == "current"
    demo.write_text(DEMO.replace('"full": [2, 3]', '"full": [2, 4]'))
    s = provenance.status(out, "demo", root)
    assert s.state == "stale" and s.changed == ["studies/demo.py:full-cases"]


def test_redraw_records_the_new_figure(tmp_path: Path) -> None:
    """``studies.redraw`` draws a committed study's figure from its table with the current code; the sidecar then
    describes the new PNG, and the result is not taken for rewritten."""
    import shutil
    full = ROOT / "reports" / "full"
    if not (full / "support_radius.csv").is_file():
        pytest.skip("no committed full-mode results")
    for suffix in (".csv", ".png", provenance.SUFFIX):
        shutil.copy(full / f"support_radius{suffix}", tmp_path)
    from studies.redraw import redraw
    before = provenance.status(tmp_path, "support_radius").state
    png = redraw(tmp_path, "support_radius")
    assert png.stat().st_size > 10_000
    assert provenance.status(tmp_path, "support_radius").state == before


def test_a_rewritten_result_is_modified_and_a_missing_record_unstamped(made) -> None:
    root, out = made
    (out / "demo.csv").write_text("a,b\n1,3\n")
    assert provenance.status(out, "demo", root).state == "modified"
    provenance.sidecar(out, "demo").unlink()
    assert provenance.status(out, "demo", root).state == "unstamped"


def test_every_committed_full_mode_result_is_stamped() -> None:
    """Each table and figure under reports/full/ has a sidecar that describes it as it is (its state against the
    current code, current or stale, is the report's to state)."""
    full = ROOT / "reports" / "full"
    if not full.is_dir():
        pytest.skip("no committed full-mode results")
    for name in provenance.studies_in(full):
        s = provenance.status(full, name)
        assert s.state in ("current", "stale"), f"{name}: {s.state} ({s.describe()})"


def test_a_result_named_apart_from_its_module_follows_that_modules_sources(tmp_path: Path) -> None:
    """The full report's own files (e.g. ``alpha_shapes.png`` by ``studies/model_figures.py``) are stamped with the
    module that made them, and go stale with its sources, not with a study of their name."""
    root, out = tmp_path / "repo", tmp_path / "full"
    _tree(root)
    out.mkdir()
    (out / "pictures.png").write_bytes(b"\x89PNG fake")
    provenance.stamp(out, "pictures", root=root, module="demo")
    record = json.loads(provenance.sidecar(out, "pictures").read_text())
    assert record["module"] == "demo" and set(record["files"]) == {"pictures.png"}
    assert "studies/helper.py" in record["sources"]          # demo's import, followed
    assert provenance.status(out, "pictures", root).state == "current"
    (root / "studies/helper.py").write_text("z = 5\n")
    assert provenance.status(out, "pictures", root).state == "stale"
