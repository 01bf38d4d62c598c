"""Markdown helpers of the report: tables as Markdown, error columns as percentages."""
from __future__ import annotations

import re
from collections.abc import Callable, Iterable

import numpy as np
import pandas as pd

#: Appends text to the report (the ``write`` of the report's buffer); every section writes through one.
Writer = Callable[[str], object]
#: Reports progress to the user (``print`` by default).
Progress = Callable[[str], object]


def pct(df: pd.DataFrame, cols: Iterable[str]) -> pd.DataFrame:
    """``df`` for printing: the fractions in ``cols`` as percentages (empty where missing), ``time_s`` to
    the millisecond, without the ``status`` and ``d_c`` columns."""
    out = df.copy()
    for c in cols:
        if c in out:
            out[c] = out[c].map(lambda v: "" if v is None or (isinstance(v, float) and np.isnan(v)) else f"{100 * v:.4g} %")
    if "time_s" in out:
        out["time_s"] = out.time_s.map(lambda v: f"{v:.3f}")
    return out.drop(columns=[c for c in ("status", "d_c") if c in out])


def md(df: pd.DataFrame) -> str:
    """``df`` as a Markdown table, without the index."""
    return df.to_markdown(index=False)


def each(values: Iterable[float], spec: str, sep: str = " / ") -> str:
    """``values`` formatted with ``spec`` and joined by ``sep`` (one per run: ``0.35 / 0.36``)."""
    return sep.join(format(v, spec) for v in values)


def span(values: Iterable[float], spec: str) -> str:
    """The range of ``values`` formatted with ``spec``: ``lo-hi``, or one value where both ends print alike."""
    v = list(values)
    lo, hi = format(min(v), spec), format(max(v), spec)
    return lo if lo == hi else f"{lo} to {hi}" if lo[0] in "+-" or hi[0] in "+-" else f"{lo}-{hi}"


def sci(value: float, spec: str = "g") -> str:
    """``value`` formatted with ``spec``, its exponent without padding (``5e-6``, not ``5e-06``)."""
    return re.sub(r"e([+-])0*(\d)", r"e\1\2", format(value, spec))
