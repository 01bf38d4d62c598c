"""The model figures (paper Figs. 6 and 8, :mod:`studies.model_figures`): drawn from the benchmark definitions,
the tracked boundary of each cloud has the loops its body has."""
from __future__ import annotations

from pathlib import Path

from studies import model_figures


def test_the_clouds_have_the_loops_of_their_bodies() -> None:
    """One loop for the rectangle, the slope and the quarter plate (its hole an arc of the outer loop); three for
    the plate with two holes cut inside it, two of them holes."""
    loops = {c.title: (len(c.boundary.loops), c.boundary.n_holes, len(c.boundary.detached))
             for c in model_figures.clouds(quick=True)}
    assert list(loops.values()) == [(1, 0, 0), (1, 0, 0), (1, 0, 0), (3, 2, 0)], loops


def test_run_writes_both_figures(tmp_path: Path) -> None:
    """``run`` writes the alpha shapes (Fig. 6) and the models (Fig. 8) as PNGs, and no temporary file beside them."""
    paths = model_figures.run(True, tmp_path, progress=lambda _: None)
    assert [p.name for p in paths] == [model_figures.ALPHA_SHAPES, model_figures.MODELS]
    for p in paths:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and p.stat().st_size > 10_000
    assert sorted(f.name for f in tmp_path.iterdir()) == sorted(p.name for p in paths)
