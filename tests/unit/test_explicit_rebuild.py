"""Re-laying the explicit solver's frame: a node thrown off the body (free particle or a stop), and a
re-tracking that fails (the run goes on with the points it carried)."""
from __future__ import annotations

import numpy as np
import pytest
from clouds import QUICK_COLUMN as QUICK

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.solvers.explicit.run import ExplicitRun


def test_a_node_thrown_off_the_body_is_free_or_stops_the_run(tmp_path):
    case = benchmarks.load("column-collapse", QUICK + ["explicit.detached=\"free\""])
    run = ExplicitRun(case, tmp_path, "key")
    run.dropped_points = 0
    x = run.X.copy()
    x[-1] = [0.5, 0.5]                               # far above and beside the column
    frame = run.lay_frame(x, np.zeros(len(x), bool))
    assert len(x) - 1 not in frame.active and frame.free[-1] and frame.free.sum() == 1
    assert frame.N[:, -1].nnz == 0                  # out of every support: a free particle
    strict = ExplicitRun(benchmarks.load("column-collapse", QUICK + ["explicit.detached=\"stop\""]), tmp_path, "key")
    with pytest.raises(ProblemError, match="left the body"):
        strict.lay_frame(x, np.zeros(len(x), bool))


def test_a_failed_re_tracking_falls_back_to_the_carried_points(tmp_path):
    """Where the alpha shape cannot be traced (a pinch it cannot split), the run goes on with the points
    it carried and tries again at the next rebuild; the failures are counted."""
    case = benchmarks.load("column-collapse", QUICK + ["explicit.initial=\"none\"", "explicit.duration=0.03",
                                                       "explicit.rebuild_strain=0.01", "explicit.relay_strain=0.01",
                                                       "explicit.save_every=1.0"])
    run = ExplicitRun(case, tmp_path, "key")
    run.start()

    def untraceable(x, free):
        raise ProblemError("alpha shape: loop is not simple at node(s) [1]")

    run.lay_frame = untraceable
    run.run(progress=False)
    assert run.rebuilds > 0 and run.relay_failures == run.rebuilds and run.transfers == 0
    assert "not simple" in run.relay_failure
    assert np.isfinite(run.x).all()
