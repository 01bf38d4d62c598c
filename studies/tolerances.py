"""The tolerances table (``tolerances.toml``): one limit per verified quantity, read by tests and report."""
from __future__ import annotations

import tomllib
from functools import cache
from pathlib import Path

FILE = Path(__file__).with_name("tolerances.toml")


@cache
def table() -> dict[str, dict]:
    """The whole table: key -> entry (``quantity``, ``reference``, ``min`` and/or ``max``, ``unit``, ``source``)."""
    return tomllib.loads(FILE.read_text())


def entry(key: str) -> dict:
    """The entry of ``key``."""
    return table()[key]


def passes(key: str, value: float) -> bool:
    """Whether ``value`` lies within the limits of ``key``."""
    e = entry(key)
    return e.get("min", -float("inf")) <= value <= e.get("max", float("inf"))


def is_dimensionless(key: str) -> bool:
    """Rates, ratios and absolute differences are shown as plain numbers, relative errors in percent."""
    return entry(key).get("unit") in ("rate", "ratio", "absolute")


def describe_limit(key: str) -> str:
    """The limits of ``key`` as text (``a .. b``, ``<= b`` or ``>= a``), relative errors in percent."""
    e = entry(key)
    pct = not is_dimensionless(key)
    fmt = (lambda v: f"{100 * v:.3g} %") if pct else (lambda v: f"{v:.3g}")
    if "min" in e and "max" in e:
        return f"{fmt(e['min'])} .. {fmt(e['max'])}"
    return f"<= {fmt(e['max'])}" if "max" in e else f">= {fmt(e['min'])}"
