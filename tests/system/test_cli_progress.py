"""Progress of the static solvers when stderr is a file: the console's own process writing plain lines
that name what runs and how much of it (the assembly's dofs, Newton's increment and iteration, the
relaxation's step), never a carriage return. The log's delay and interval are set to 0 in the child, so
that runs of a second show what a long one shows after its first seconds."""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

from ctmrpim import progress

#: the child: every run "long" at once, each status written; each argument list run in turn
CHILD = """
import json, sys
from ctmrpim import progress
progress.DELAY = 0.0
progress.LOG_INTERVAL = 0.0
from ctmrpim.cli import main
for args in json.loads(sys.argv[1]):
    print("exit", main(args))
"""
RUNS = {
    "linear": ["cantilever", "--set", "nodes.grid=[17,5]"],
    "newton": ["tip-load", "--set", "nodes.grid=[17,3]", "--set", "loading.steps=4"],
    "relaxation": ["self-weight", "--set", 'problem.analysis="dynamic"', "--set", 'material.model="mohr-coulomb"',
                   "--set", "material.c=1e9", "--set", "material.phi=30"],
}


def test_static_progress_in_a_log_file_is_plain_lines_with_counts(tmp_path: Path) -> None:
    runs = [["run", *args, "--out", str(tmp_path / name)] for name, args in RUNS.items()]
    log = tmp_path / "stderr.log"
    with open(log, "w") as stderr:
        proc = subprocess.run([sys.executable, "-c", CHILD, json.dumps(runs)], stdout=subprocess.PIPE,
                              stderr=stderr, text=True, timeout=300, cwd=tmp_path)
    assert proc.returncode == 0 and re.findall(r"^exit (\d+)$", proc.stdout, re.M) == ["0", "0", "0"], log.read_text()
    text = log.read_text()
    assert "\r" not in text and "\x1b" not in text and "Traceback" not in text
    lines = text.splitlines()
    assert all(line.startswith("ctmrpim: ") for line in lines), [x for x in lines if not x.startswith("ctmrpim: ")]
    titles = [line for line in lines if not line.startswith("ctmrpim: [")]
    assert titles[0] == "ctmrpim: cantilever (linear, ctm-rpim, 17 x 5 nodes)"
    # linear: the assembly and the solve name their sizes (17 x 5 nodes: 170 dofs, 160 of them free)
    assert re.search(r"\] .*assembly \d+\.\d\d s \(\d+ integration points, 170 dofs, \d+ nonzeros\)", text), text
    assert re.search(r"solve \d+\.\d\d s \(160 free dofs\)", text)
    # Newton: which increment of how many, the iteration and the residual
    for k in range(1, 5):
        assert re.search(rf"\] increment {k}/4 \(load factor {k / 4:g}\), iteration 1, residual \d\.\d\de[-+]\d\d "
                         "of the loads", text), k
    # dynamic relaxation: its step of the most it may take, and how far from rest
    assert re.search(r"\] dynamic relaxation: step 100/3000, out-of-balance force \d\.\d\de[-+]\d\d of the loads "
                     r"\(at rest below 0\.0001\)", text)


def test_a_stage_labels_the_statuses_within_it() -> None:
    """A strength-reduction level labels the Newton or relaxation statuses it runs; outside, none."""
    stream = __import__("io").StringIO()
    with progress.reporting(progress.Progress(stream, live=False, title="demo", delay=0.0, log_interval=0.0)) as rep:
        with rep.stage("SRF 1.3500"):
            rep.status("increment 1/4")
        rep.status("increment 2/4")
    lines = stream.getvalue().splitlines()
    assert lines[1].endswith("] SRF 1.3500: increment 1/4") and lines[2].endswith("] increment 2/4")
    with progress.SILENT.stage("SRF 1"):       # the silent reporter takes a stage too, and shows nothing
        progress.SILENT.status("x")
