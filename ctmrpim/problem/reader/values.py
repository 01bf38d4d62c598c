"""Reading values: numbers and fields as expressions of the ``[parameters]``, and defaults recorded."""
from __future__ import annotations

from typing import Any

from ctmrpim.errors import ProblemError
from ctmrpim.problem.expressions import CONSTANTS, FUNCTIONS, Field, constant


def read_parameters(table: dict) -> dict[str, float]:
    """The ``[parameters]`` evaluated in file order (each may use the ones before it)."""
    params: dict[str, float] = {}
    for name, value in table.items():
        if not name.isidentifier():
            raise ProblemError(f"{name!r} is not a valid name", key=f"parameters.{name}")
        if name in ("x", "y", "t"):
            raise ProblemError(f"{name!r} is reserved for the coordinates and time", key=f"parameters.{name}")
        if name in CONSTANTS or name in FUNCTIONS:
            # it would silently replace the constant (pi, e) or hide the function in every expression
            what = f"the constant {name} = {CONSTANTS[name]:.6g}" if name in CONSTANTS else f"the function {name}()"
            raise ProblemError(f"{name!r} would replace {what}: choose another name", key=f"parameters.{name}")
        try:
            params[name] = constant(value, params)
        except ProblemError as exc:
            raise exc.at(key=f"parameters.{name}") from None
    return params


class Values:
    """The values of one problem file: its tables, its parameters, and the defaults applied so far
    (``section.key = value``, in the order they were applied, for ``summary.json``)."""

    def __init__(self, raw: dict, parameters: dict[str, float]) -> None:
        self.raw = raw
        self.parameters = parameters
        self.defaults: list[str] = []

    def get(self, section: str, key: str, default: Any) -> Any:
        """``section.key`` as written, else ``default`` (recorded)."""
        table = self.raw.get(section, {})
        if key in table:
            return table[key]
        self.record(section, key, default)
        return default

    def record(self, section: str, key: str, default: Any) -> None:
        """Note that ``section.key`` was not given and ``default`` applies."""
        self.defaults.append(f"{section}.{key} = {default!r}")

    def number(self, value: Any, key: str) -> float:
        """A number, or an expression of the parameters, as a float; errors name ``key``."""
        try:
            return constant(value, self.parameters)
        except ProblemError as exc:
            raise exc.at(key=key) from None

    def field(self, value: Any, key: str) -> Field:
        """An expression of x, y, t and the parameters; errors name ``key``."""
        try:
            return Field(value, self.parameters)
        except ProblemError as exc:
            raise exc.at(key=key) from None
