"""The README's examples are tests: its "Python API" block runs as written, on a coarser grid."""
from __future__ import annotations

import math
import re
from pathlib import Path

import ctmrpim

README = Path(__file__).resolve().parents[2] / "README.md"


def python_api_block() -> str:
    """The ```python block under the README's heading "## Python API"."""
    section = README.read_text().split("\n## Python API\n", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"^```python\n(.*?)^```", section, re.M | re.S)
    assert len(blocks) == 1, "the Python API section holds one python block"
    return blocks[0]


def test_python_api_example_runs(solutions, monkeypatch, capsys) -> None:
    """The block with the cantilever's grid 65 x 17 made 17 x 5 (its solves shared with the verification tests):
    it prints the tip deflection and the two energy-norm errors."""
    code = python_api_block()
    assert code.count("[65, 17]") == 1
    monkeypatch.setattr(ctmrpim, "solve", solutions.solve)
    exec(compile(code.replace("[65, 17]", "[17, 5]"), str(README), "exec"), {})
    printed = capsys.readouterr().out.split()
    assert len(printed) == 3
    tip, ours, fem = map(float, printed)
    assert tip < 0 and all(math.isfinite(v) for v in (tip, ours, fem))
    assert 0 < fem < ours < 1    # P2 on the same nodes beats CTM-RPIM in energy
    case = ctmrpim.load_case("cantilever", ["nodes.grid=[17, 5]"])
    assert tip == solutions(case).probes["tip"]["uy"]
