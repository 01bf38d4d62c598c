"""What a sweep worker hands back (studies.sweep.run_case): away from the client's folders it returns the files it
wrote, and the client stores them; a worker of another code version refuses the case (the cluster itself:
system/test_dask.py)."""
from __future__ import annotations

import json

from studies.sweep import CaseSpec, Sweep, method_version, resolve_case, run_case

SPEC = CaseSpec("cantilever", ("nodes.grid=[17, 5]",))


def test_scratch_run_returns_its_files_and_the_client_stores_them(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)        # a worker's working directory: nothing may land there
    case, key = resolve_case(SPEC)
    run = run_case(SPEC, case, key, method_version(SPEC.solver), worker=False)
    assert run.status["status"] == "ok" and run.status["hash"] == key
    assert list(run.files) == ["summary.json"] and list(tmp_path.iterdir()) == []
    sweep = Sweep(tmp_path / "client", progress=False)
    sweep.store(key, run)
    out = sweep.run([SPEC])            # the stored case is done: served from the cache
    assert sweep.computed == 0 and out[0].status == "ok"
    assert out[0].summary == json.loads(run.files["summary.json"])


def test_worker_of_another_code_version_refuses(tmp_path) -> None:
    case, key = resolve_case(SPEC)
    run = run_case(SPEC, case, key, "0.0.0+other", worker=False)
    assert run.status["status"] == "failed" and not run.files
    assert "0.0.0+other" in run.status["error"] and method_version(SPEC.solver) in run.status["error"]
