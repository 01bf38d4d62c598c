"""The VTU time series (ctmrpim.io.vtu): written, resumed and read back."""
from __future__ import annotations

import meshio
import numpy as np


def test_series_writer_round_trip(tmp_path):
    from ctmrpim.io.vtu import SeriesWriter, read_pvd
    writer = SeriesWriter(tmp_path)
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    for t in (0.0, 0.5):
        writer.add(t, pts + t, [("line", np.array([[0, 1], [1, 2], [2, 0]]))], {"u": np.full((3, 3), t)})
    resumed = SeriesWriter(tmp_path, writer.entries)
    resumed.add(1.0, pts, [], {"u": np.zeros((3, 3))})
    entries = read_pvd(tmp_path / "result.pvd")
    assert [t for t, _ in entries] == [0.0, 0.5, 1.0]
    m = meshio.read(entries[1][1])
    assert np.allclose(m.points[:, :2], pts + 0.5) and np.allclose(m.point_data["u"], 0.5)
