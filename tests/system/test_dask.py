"""The sweep executor on a Dask cluster (a test dependency, never skipped): a local cluster gives the results of
local processes, bit for bit; an unreachable scheduler is a clear error (after the client's 10 s timeout)."""
from __future__ import annotations

import pytest

from studies.sweep import CaseSpec, Sweep

pytestmark = pytest.mark.slow

#: the executor's cases of unit/test_sweep.py
SPECS = [CaseSpec("cantilever", ("nodes.grid=[17, 5]", f"method.eta={eta}"), labels=(("eta", eta),))
         for eta in (3.5, 5.0, 6.5)] + [CaseSpec("cantilever", ("nodes.grid=[17, 5]",), "fem", "q1")]


def numbers(outcomes) -> list:
    return [(o.status, o.summary and o.summary["probes"], o.summary and o.summary["errors"]) for o in outcomes]


def test_dask_local_cluster_gives_identical_results(tmp_path, sweep) -> None:
    """Local processes (the run's study cache: the studies' cases of the same cantilever are shared) against a
    local Dask cluster."""
    from dask import distributed  # a test dependency: never skipped
    local = sweep.run(SPECS)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        remote = Sweep(tmp_path / "dask", scheduler=cluster.scheduler_address, progress=False).run(SPECS)
    assert numbers(local) == numbers(remote)


def test_unreachable_scheduler_is_a_clear_error(tmp_path) -> None:
    from ctmrpim.errors import ProblemError

    with pytest.raises(ProblemError, match="Dask scheduler"):
        Sweep(tmp_path, scheduler="tcp://127.0.0.1:9", progress=False).run(SPECS[:1])
