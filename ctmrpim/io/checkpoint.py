"""Checkpoints of long explicit runs: everything the next step needs, in float64, in one ``.npz``.

A run resumed from a checkpoint ends in the same state as an uninterrupted run (docs/design.md, 'Explicit
dynamics'): the file holds the node positions and velocities, the state at the integration points, the
positions the current configuration was built on (it is rebuilt from them, bit for bit, on resume), the
time step, counters, energy accounts and history, and the hash of the resolved input and of the code, so
that a checkpoint is never resumed with another problem or another solver. It is written atomically: a
kill during the write leaves the previous checkpoint in place.

Its metadata is strict JSON like every JSON ctmrpim writes, but a resume must get back exactly what was
saved, infinities included (the gravity stage's out-of-balance force starts at infinity), so a non-finite
number is stored as ``{"float": "inf"}`` (or ``"-inf"``, ``"nan"``) and turned back on loading.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ctmrpim.errors import ProblemError
from ctmrpim.io.atomic import atomic_write, signals_deferred
from ctmrpim.io.summary import to_jsonable

NAME = "checkpoint.npz"
#: the key of a non-finite number in the metadata
NONFINITE = "float"


def _encode(value: Any) -> Any:
    """``value`` (JSON-able) with each non-finite float as ``{"float": repr}``."""
    if isinstance(value, dict):
        return {k: _encode(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_encode(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return {NONFINITE: repr(value)}
    return value


def _decode(value: Any) -> Any:
    """The inverse of :func:`_encode`."""
    if isinstance(value, dict):
        if len(value) == 1 and isinstance(value.get(NONFINITE), str):
            return float(value[NONFINITE])
        return {k: _decode(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_decode(v) for v in value]
    return value


def save_checkpoint(folder: Path, key: str, meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> Path:
    """Write ``meta`` (JSON-able) with ``key`` (the hash of the resolved input and the code) and ``arrays`` to
    ``folder/checkpoint.npz``, atomically; its path."""
    path = Path(folder) / NAME
    payload = {f"a_{k}": np.asarray(v) for k, v in arrays.items()}
    payload["meta"] = np.array(json.dumps(_encode(to_jsonable({**meta, "key": key})), allow_nan=False))

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:          # a file object: np.savez would append ".npz" to a path
            np.savez(fh, **payload)

    with signals_deferred():                 # Ctrl-C inside np.savez breaks its archive's close (atomic.py)
        atomic_write(path, write)
    return path


def load_checkpoint(folder: Path, key: str) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """(meta, arrays) of the folder's checkpoint, or a ProblemError saying why it cannot be resumed."""
    path = Path(folder) / NAME
    if not path.is_file():
        raise ProblemError(f"no checkpoint to resume in {str(folder)!r} (expected {NAME}); run without --resume",
                           key="--resume")
    try:
        with np.load(path) as data:
            meta = _decode(json.loads(str(data["meta"])))
            arrays = {k[2:]: data[k] for k in data.files if k.startswith("a_")}
    except (OSError, ValueError, KeyError) as exc:
        raise ProblemError(f"the checkpoint {str(path)!r} cannot be read ({exc})", key="--resume") from None
    if meta.get("key") != key:
        raise ProblemError(f"the checkpoint in {str(folder)!r} belongs to another problem, setting or code version; "
                           "run without --resume to start again", key="--resume")
    return meta, arrays
