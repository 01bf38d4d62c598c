"""``summary.json``: the fully resolved input, counts, timings, probes, errors and history of one run."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ctmrpim.io.atomic import atomic_write_text
from ctmrpim.result import Result
from ctmrpim.version import __version__


def to_jsonable(obj: Any) -> Any:
    """``obj`` with numpy arrays and scalars turned into lists and Python numbers (for ``json.dumps``)."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def summary_dict(result: Result, source: str) -> dict[str, Any]:
    """The content of ``summary.json``: version, ``source`` file, method, resolved parameters, defaults applied,
    counts, timings, probes, errors, outcome and history of ``result``."""
    return {
        "ctmrpim_version": __version__,
        "source": source,
        "method": result.method,
        "parameters": result.parameters,
        "defaults_applied": result.defaults,
        "counts": result.counts,
        "timings": result.timings,
        "probes": result.probes,
        "errors": result.errors,
        **result.outcome,
        **({"history": result.history} if result.history else {}),
    }


def write_summary(result: Result, out_dir: Path, source: str) -> Path:
    """Write ``out_dir/summary.json`` atomically; its path."""
    path = Path(out_dir) / "summary.json"
    atomic_write_text(path, json.dumps(to_jsonable(summary_dict(result, source)), indent=2) + "\n")
    return path
