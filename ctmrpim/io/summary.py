"""``summary.json``: the fully resolved input, counts, timings, probes, errors and history of one run.

Every JSON file ctmrpim writes is strict JSON (``allow_nan=False``): a number that is not finite (a relative
error whose exact reference is zero, 0/0 or x/0) is written as ``null``, and the summary's ``notes`` say
which value was undefined and why, so that every JSON reader accepts the file and nobody mistakes the gap
for a measured value. The ``notes`` also keep what the command line warned about during the run (``notes``
of :func:`write_summary`).
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Iterable

import numpy as np

from ctmrpim.io.atomic import atomic_write_text
from ctmrpim.result import Result
from ctmrpim.version import __version__

#: why a value under this key of the summary can be undefined
UNDEFINED_BECAUSE = {
    "errors": "a relative error whose exact reference value is zero (0/0 or x/0) has no value",
}


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


def finite_jsonable(obj: Any, where: str = "") -> tuple[Any, list[str]]:
    """:func:`to_jsonable` of ``obj`` with every NaN and infinity replaced by None; and a note for each, naming
    the value by its dotted path (``errors.energy``) and what it was (with why, where that is known)."""
    notes: list[str] = []

    def walk(value: Any, path: str) -> Any:
        if isinstance(value, dict):
            return {k: walk(v, f"{path}.{k}" if path else k) for k, v in value.items()}
        if isinstance(value, list):
            return [walk(v, f"{path}[{i}]") for i, v in enumerate(value)]
        if isinstance(value, float) and not math.isfinite(value):
            what = "NaN" if math.isnan(value) else ("+infinity" if value > 0 else "-infinity")
            why = UNDEFINED_BECAUSE.get(path.split(".")[0].split("[")[0])
            notes.append(f"{path} is undefined ({what}), written as null" + (f": {why}" if why else ""))
            return None
        return value

    return walk(to_jsonable(obj), where), notes


def json_text(obj: Any, indent: int | None = 2) -> str:
    """Strict JSON text of ``obj`` (numpy converted, non-finite numbers as null), ending in a newline."""
    return json.dumps(finite_jsonable(obj)[0], indent=indent, allow_nan=False) + "\n"


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


def _write(content: dict[str, Any], out_dir: Path) -> Path:
    """Write ``content`` as strict JSON to ``out_dir/summary.json`` atomically, with ``notes`` on the values
    that were undefined; its path."""
    data, notes = finite_jsonable(content)
    if notes:
        data["notes"] = data.get("notes", []) + notes
    path = Path(out_dir) / "summary.json"
    atomic_write_text(path, json.dumps(data, indent=2, allow_nan=False) + "\n")
    return path


def write_summary(result: Result, out_dir: Path, source: str, notes: Iterable[str] = ()) -> Path:
    """Write ``out_dir/summary.json`` atomically (strict JSON, see the module), with ``notes`` on the run (the
    warnings it printed) first in its ``notes``; its path."""
    return _write({**summary_dict(result, source), **_notes(notes)}, out_dir)


def write_partial_summary(out_dir: Path, *, source: str, method: str, parameters: dict[str, Any],
                          defaults: list[str], status: str, error: str, history: list[dict[str, Any]],
                          seconds: float, notes: Iterable[str] = ()) -> Path:
    """Write the ``summary.json`` of a run that gave no result (``status`` "not converged"): the resolved
    input, the reason, the ``history`` of what converged before it stopped, the seconds it ran and ``notes``
    on the run; its path."""
    return _write({"ctmrpim_version": __version__, "status": status, "error": error, "source": source,
                   "method": method, "parameters": parameters, "defaults_applied": defaults,
                   "timings": {"total": seconds}, "history": history, **_notes(notes)}, out_dir)


def _notes(notes: Iterable[str]) -> dict[str, list[str]]:
    """``{"notes": [...]}`` if there are any, else nothing: a summary without notes has no such key."""
    notes = list(notes)
    return {"notes": notes} if notes else {}
