"""The sweep executor on a Dask cluster (a test dependency, never skipped): a scheduler and workers started in
folders of their own, as on a real cluster, give the study's table of a local run; a local cluster gives the
results of local processes, bit for bit; a worker of another code version refuses its cases; an unreachable
scheduler is a clear error (after the client's 10 s timeout)."""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest

from studies.sweep import CaseSpec, Sweep

pytestmark = pytest.mark.slow

#: the executor's cases of unit/test_sweep.py
SPECS = [CaseSpec("cantilever", ("nodes.grid=[17, 5]", f"method.eta={eta}"), labels=(("eta", eta),))
         for eta in (3.5, 5.0, 6.5)] + [CaseSpec("cantilever", ("nodes.grid=[17, 5]",), "fem", "q1")]
BIN = Path(sys.executable).parent    # the dask and ctmrpim commands of this environment
TIMINGS = ["time_s"]                 # the columns that differ from run to run


def numbers(outcomes) -> list:
    return [(o.status, o.summary and o.summary["probes"], o.summary and o.summary["errors"]) for o in outcomes]


def study(cwd: Path, *options: str) -> pd.DataFrame:
    """Run ``ctmrpim study shape-parameter --quick`` in ``cwd`` (its cache under ``cwd/runs``); its CSV."""
    done = subprocess.run([str(BIN / "ctmrpim"), "study", "shape-parameter", "--quick", "--out", "out", *options],
                          cwd=cwd, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stdout + done.stderr
    return pd.read_csv(cwd / "out" / "shape_parameter.csv")


def stop(process: subprocess.Popen) -> None:
    """End a process we started: SIGTERM (a worker's nanny closes its workers), SIGKILL if it hangs."""
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(30)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def test_scheduler_and_workers_in_their_own_folders_give_the_local_table(tmp_path) -> None:
    """``dask scheduler`` and ``dask worker`` started in folders of their own (a real cluster: the workers' working
    directory is not the client's): every case comes back through Dask, the client writes the case folders, nothing
    lands in the workers' folder, and the table equals a local run's (timings aside)."""
    folders = {name: tmp_path / name for name in ("scheduler", "workers", "client", "local")}
    for f in folders.values():
        f.mkdir()
    address_file = folders["scheduler"] / "scheduler.json"
    scheduler = subprocess.Popen([str(BIN / "dask"), "scheduler", "--host", "127.0.0.1", "--port", "0",
                                  "--no-dashboard", "--scheduler-file", str(address_file)],
                                 cwd=folders["scheduler"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    workers = None
    try:
        deadline = time.monotonic() + 60
        while not address_file.is_file() and time.monotonic() < deadline:
            time.sleep(0.2)
        address = json.loads(address_file.read_text())["address"]
        workers = subprocess.Popen([str(BIN / "dask"), "worker", address, "--nworkers", "2", "--nthreads", "1",
                                    "--no-dashboard", "--local-directory", str(folders["workers"] / "space")],
                                   cwd=folders["workers"], stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        start = time.perf_counter()
        remote = study(folders["client"], "--scheduler", address)
        print(f"study through the cluster: {time.perf_counter() - start:.1f} s")
    finally:
        if workers is not None:
            stop(workers)
        stop(scheduler)
    start = time.perf_counter()
    local = study(folders["local"], "--workers", "2")
    print(f"local study: {time.perf_counter() - start:.1f} s")
    cases = sorted((folders["client"] / "runs" / "sweeps").iterdir())
    assert len(cases) == len(local) and all((c / "summary.json").is_file() and (c / "status.json").is_file()
                                            for c in cases)
    assert not (folders["workers"] / "runs").exists()
    assert (local.status == "ok").all(), local.T
    pd.testing.assert_frame_equal(remote.drop(columns=TIMINGS), local.drop(columns=TIMINGS))


@pytest.fixture(scope="module")
def cluster():
    """A local Dask cluster: two worker processes of one thread each."""
    from dask import distributed  # a test dependency: never skipped

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        yield cluster


def test_dask_local_cluster_gives_identical_results(tmp_path, sweep, cluster) -> None:
    """Local processes (the run's study cache: the studies' cases of the same cantilever are shared) against a
    local Dask cluster."""
    local = sweep.run(SPECS)
    remote = Sweep(tmp_path / "dask", scheduler=cluster.scheduler_address, progress=False).run(SPECS)
    assert numbers(local) == numbers(remote)
    assert all((o.folder / "summary.json").is_file() for o in remote)


def test_worker_of_another_code_version_refuses_the_case(tmp_path, cluster, monkeypatch) -> None:
    """A client whose code version differs from the workers' (here: the client's stands in for another one; the
    workers are processes of their own) gets its cases refused: each records status failed with both versions
    named, the sweep ends with one clear error, and the record is not cached, so a run with matching code computes
    the case."""
    import studies.sweep as sweep_module
    from ctmrpim.errors import ProblemError

    real = sweep_module.method_version("ctm-rpim")
    with monkeypatch.context() as patch:
        patch.setattr(sweep_module, "method_version", lambda name: "0.0.0+client")
        key = sweep_module.case_hash(SPECS[0])
        runner = Sweep(tmp_path, scheduler=cluster.scheduler_address, progress=False)
        with pytest.raises(ProblemError, match=r"1 of 1 cases could not run \(worker .* has code version") as error:
            runner.run(SPECS[:1])
        with pytest.raises(ProblemError):
            runner.run(SPECS[:1])
        assert runner.computed == 1
    assert real in str(error.value) and "0.0.0+client" in str(error.value)
    status = json.loads((runner.folder(key) / "status.json").read_text())
    assert status["status"] == "failed" and real in status["error"]
    assert not (runner.folder(key) / "summary.json").exists()


def test_unreachable_scheduler_is_a_clear_error(tmp_path) -> None:
    from ctmrpim.errors import ProblemError

    with pytest.raises(ProblemError, match="Dask scheduler"):
        Sweep(tmp_path, scheduler="tcp://127.0.0.1:9", progress=False).run(SPECS[:1])
