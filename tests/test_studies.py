"""Every study's quick mode, run through the sweep executor, checked against the tolerances table."""
from __future__ import annotations

import pandas as pd
import pytest
from verify import check

import studies
from studies import claims
from studies.sweep import Sweep


@pytest.fixture(scope="module")
def sweep(tmp_path_factory) -> Sweep:
    return Sweep(tmp_path_factory.mktemp("cache"), workers=2, progress=False)


@pytest.fixture(scope="module")
def tables(tmp_path_factory, sweep) -> dict[str, pd.DataFrame]:
    root = tmp_path_factory.mktemp("studies")
    return {name: studies.run(name, True, root / "reports", sweep, progress=lambda *_: None)
            for name in studies.NAMES}


def test_quick_report(tables, sweep, tmp_path) -> None:
    """The main job: every section and figure is written and every check passes (the studies' cases
    come from the shared cache, so this only adds the report's own work)."""
    from studies.report import make_report

    path = make_report(quick=True, out_dir=tmp_path, sweep=sweep, progress=lambda *_: None)
    text = path.read_text()
    assert "FAIL" not in text
    for name in [*studies.NAMES, "deformed_shapes"]:
        assert f"({name}.png)" in text and (tmp_path / f"{name}.png").is_file()
    assert sweep.computed == 0


def test_every_case_succeeds(tables) -> None:
    for name, df in tables.items():
        assert (df.status == "ok").all(), f"{name}: {df[df.status != 'ok'].to_dict('records')}"


@pytest.mark.parametrize("key", sorted(claims.CLAIMS))
def test_paper_claim(tables, key: str) -> None:
    values = claims.evaluate(tables)
    check(key, values[key])


def test_outputs_written(tables, tmp_path_factory) -> None:
    reports = next(p for p in tmp_path_factory.getbasetemp().rglob("reports") if p.is_dir())
    for name in studies.NAMES:
        assert (reports / f"{name}.csv").stat().st_size > 0
        assert (reports / f"{name}.png").read_bytes()[:4] == b"\x89PNG"
        assert len(pd.read_csv(reports / f"{name}.csv")) == len(tables[name])


def test_tip_load_study_against_the_elastica(tables) -> None:
    tip = tables["tip_load"]
    ours = tip[tip.method == "ctm-rpim"]
    shear, corner = ours[ours.load == "end shear"], ours[ours.load == "corner"]
    check("tip-load-tl-elastica", shear.w_rel_diff.abs().max())
    check("tip-load-tl-elastica-shortening", shear.u_rel_diff.abs().max())
    check("tip-load-corner-tl-elastica", corner.w_rel_diff.abs().max())


def test_end_moment_study(tables) -> None:
    check("end-moment-tl-quarter", tables["end_moment"].tip_distance_over_L.iloc[0])


def test_time_to_accuracy_targets(tables) -> None:
    from studies.time_to_accuracy import targets_table

    t = targets_table(tables["time_to_accuracy"]).set_index("method")
    assert t.loc["fem-p2", "time_to_0.1%"] > 0
    assert t.loc["ctm-rpim", "time_to_1%"] > 0
