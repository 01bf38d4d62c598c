"""The sweep executor (studies.sweep): caching by resolved input, resume, failures, local processes against
in-process (on a Dask cluster: system/test_dask.py)."""
from __future__ import annotations

import json
from pathlib import Path

from studies.sweep import CaseSpec, Sweep, case_hash

SPECS = [CaseSpec("cantilever", ("nodes.grid=[17, 5]", f"method.eta={eta}"), labels=(("eta", eta),))
         for eta in (3.5, 5.0, 6.5)] + [CaseSpec("cantilever", ("nodes.grid=[17, 5]",), "fem", "q1")]
BAD = CaseSpec("cantilever", ("nodes.grid=[17, 5]", "method.support_radius=0.5"))


def numbers(outcomes) -> list:
    return [(o.status, o.summary and o.summary["probes"], o.summary and o.summary["errors"]) for o in outcomes]


def test_hash_follows_the_resolved_input() -> None:
    a = case_hash(CaseSpec("cantilever"))
    assert a == case_hash(CaseSpec("cantilever", ("nodes.grid=[33, 9]",)))   # the default, spelt out
    assert a != case_hash(CaseSpec("cantilever", ("method.eta=5.5",)))
    assert a != case_hash(CaseSpec("cantilever", (), "fem", "q1"))


def test_cache_key_hashes_only_the_code_that_computes_results(tmp_path) -> None:
    """Editing the command line's help, a study or the report's prose invalidates no cached case and no
    checkpoint: the key hashes the core without ``cli.py`` (and the method's own package), never
    ``studies/``; editing a solver module does change it."""
    import shutil

    import reference_fem
    from ctmrpim.io.provenance import PACKAGE, PRESENTATION, hashed_files, source_hash
    from studies.sweep import method_version

    hashed = hashed_files(PACKAGE, PRESENTATION)
    assert hashed and all(PACKAGE in f.parents for f in hashed)
    assert PACKAGE / "cli.py" not in hashed and PACKAGE / "discretisation" / "rpim.py" in hashed
    copy = tmp_path / "ctmrpim"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    before = source_hash(copy, PRESENTATION)
    (copy / "cli.py").write_text((copy / "cli.py").read_text().replace("list the benchmark problems", "list them"))
    assert source_hash(copy, PRESENTATION) == before
    rpim = copy / "discretisation" / "rpim.py"
    rpim.write_text(rpim.read_text() + "\n# a comment, and a docstring edited\n".replace("docstring", "doc"))
    text = rpim.read_text()
    rpim.write_text(text.replace('"""', '"""Edited. ', 1))
    assert source_hash(copy, PRESENTATION) == before   # comments and docstrings compute nothing
    rpim.write_text(text + "\nEDITED = 1\n")
    assert source_hash(copy, PRESENTATION) != before
    # the finite-element method's version adds reference_fem's sources, and nothing of studies/
    assert method_version("fem").startswith(method_version("ctm-rpim") + "+reference_fem-")
    assert method_version("fem").endswith(source_hash(Path(reference_fem.__file__).parent)[:16])


def test_resume_computes_only_what_is_missing(tmp_path) -> None:
    first = Sweep(tmp_path, progress=False)
    first.run(SPECS[:2])                       # an "interrupted" sweep: two cases done
    assert first.computed == 2
    mtimes = {p: p.stat().st_mtime_ns for p in tmp_path.rglob("summary.json")}
    again = Sweep(tmp_path, progress=False)
    out = again.run(SPECS)
    assert again.computed == 2 and [o.cached for o in out] == [True, True, False, False]
    assert {p: p.stat().st_mtime_ns for p in mtimes} == mtimes   # the finished cases were not redone
    # a case whose status record is missing (killed while writing) counts as not done
    (out[3].folder / "status.json").unlink()
    third = Sweep(tmp_path, progress=False)
    third.run(SPECS)
    assert third.computed == 1


def test_failed_case_keeps_its_error_and_is_retried_on_request(tmp_path) -> None:
    out = Sweep(tmp_path, progress=False).run([BAD])
    assert out[0].status == "error" and "support radius" in out[0].error
    status = json.loads((out[0].folder / "status.json").read_text())
    assert status["status"] == "error" and status["end"] >= status["start"]
    again = Sweep(tmp_path, progress=False)
    again.run([BAD])
    assert again.computed == 0
    retry = Sweep(tmp_path, progress=False, retry_failed=True)
    retry.run([BAD])
    assert retry.computed == 1


def test_processes_and_in_process_agree(tmp_path) -> None:
    serial = Sweep(tmp_path / "a", progress=False).run(SPECS)
    parallel = Sweep(tmp_path / "b", workers=2, progress=False).run(SPECS)
    assert numbers(serial) == numbers(parallel)


def test_warm_up_compiles_the_kernels_that_large_linear_cases_take() -> None:
    """The kernels that the linear path takes above the compiled thresholds are compiled (or loaded) by the
    warm-up, before any timed case, so that no case's wall time holds their compilation. The studies that compare
    wall times of linear solves (time-to-accuracy, node density, integration schemes) take the gradient correction
    as coefficients applied in the stiffness kernel: ``vci_kernels.corrected`` (the corrected gradients as arrays,
    for the plastic and large-deformation solvers) is not on their path, at any grid or scheme, so it is not asked
    of the warm-up. (The nonlinear schemes' time ratios do take it; the warm-up does not cover the nonlinear
    solvers.)"""
    from ctmrpim.discretisation import rpim_kernels, stiffness_kernels, vci_kernels
    from ctmrpim.solvers import free_block_kernels
    from studies import sweep

    sweep._warm = False
    sweep._warm_up()
    kernels = (rpim_kernels.support_counts, rpim_kernels.rpim_rows, stiffness_kernels.node_pattern_rows,
               stiffness_kernels.stiffness_rows, stiffness_kernels.mirror_lower, free_block_kernels.constrained_block,
               free_block_kernels.symmetric_matvec, free_block_kernels.csr_matvec,
               free_block_kernels.lower_bandwidth, free_block_kernels.fill_lower_band, vci_kernels.moments)
    assert [k.py_func.__name__ for k in kernels if not k.signatures] == []
