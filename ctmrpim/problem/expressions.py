"""Safe arithmetic expressions for problem files.

A problem file's expressions (`"P/(2*I)*(W**2/4 - y**2)"`, `"x == L and y > 0"`) are parsed with
:func:`ast.parse` and checked node by node against a whitelist; the checked tree is then walked by the
small interpreter below over numpy arrays. Nothing is ever passed to ``eval`` or ``compile``, so a
problem file cannot run code: attribute access, subscripts, lambdas, comprehensions, keyword arguments
and unknown names are rejected with the expression and the offending part named.
"""
from __future__ import annotations

import ast
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ctmrpim.errors import ProblemError

#: Functions an expression may call, by name.
FUNCTIONS: dict[str, Any] = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan,
    "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan, "atan2": np.arctan2,
    "arcsin": np.arcsin, "arccos": np.arccos, "arctan": np.arctan, "arctan2": np.arctan2,
    "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh,
    "exp": np.exp, "log": np.log, "log10": np.log10, "sqrt": np.sqrt,
    "abs": np.abs, "hypot": np.hypot, "min": np.minimum, "max": np.maximum,
    "floor": np.floor, "ceil": np.ceil, "sign": np.sign, "where": np.where,
    "radians": np.radians, "degrees": np.degrees,
}
#: Arguments each function takes. numpy ufuncs accept an extra positional ``out`` array, so
#: ``sin(x, y)`` would overwrite the caller's y coordinates in place; ``where`` with one argument
#: returns index arrays, not a field. Both are rejected when the expression is checked.
ARITY: dict[str, int] = {name: f.nin for name, f in FUNCTIONS.items() if isinstance(f, np.ufunc)} | {"where": 3}
#: Names that are always defined.
CONSTANTS: dict[str, float] = {"pi": math.pi, "e": math.e}
#: Coordinates and time: the free variables of a field expression.
VARIABLES = ("x", "y", "t")

_BINOPS = {
    ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply, ast.Div: np.divide,
    ast.Pow: np.power, ast.Mod: np.mod,
}
_UNARY = {ast.USub: np.negative, ast.UAdd: np.positive, ast.Not: np.logical_not}
_COMPARE = (ast.Eq, ast.NotEq, ast.Lt, ast.LtE, ast.Gt, ast.GtE)


class Expression:
    """A checked expression; call :meth:`evaluate` with values for its names."""

    def __init__(self, text: str | float | int, allowed: frozenset[str] | set[str] = frozenset(VARIABLES)) -> None:
        if isinstance(text, bool) or not isinstance(text, (str, int, float)):
            raise ProblemError(f"expected a number or an expression string, got {text!r}")
        self.text = str(text)
        self.names: set[str] = set()
        try:
            self._tree = ast.parse(self.text.strip(), mode="eval").body
            self._check(self._tree, set(allowed) | set(CONSTANTS))
        except SyntaxError as exc:
            raise ProblemError(f"expression {self.text!r} is not valid arithmetic ({exc.msg})") from None
        except (RecursionError, MemoryError):  # the parser and the checker recurse over the nesting
            raise ProblemError(f"expression {_short(self.text)!r} is nested too deeply") from None

    def __repr__(self) -> str:
        return f"Expression({self.text!r})"

    # -- checking ---------------------------------------------------------------------------------
    def _reject(self, node: ast.AST, why: str) -> ProblemError:
        part = ast.get_source_segment(self.text.strip(), node) or type(node).__name__
        return ProblemError(f"expression {self.text!r}: {why} ({part!r})")

    def _check(self, node: ast.AST, allowed: set[str]) -> None:
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
                raise self._reject(node, "only numbers are allowed as constants")
        elif isinstance(node, ast.Name):
            if node.id in FUNCTIONS and node.id not in allowed:
                raise self._reject(node, f"function {node.id!r} must be called")
            if node.id not in allowed:
                raise self._reject(node, f"unknown name {node.id!r}; known: {', '.join(sorted(allowed))}")
            self.names.add(node.id)
        elif isinstance(node, ast.BinOp):
            if type(node.op) not in _BINOPS:
                raise self._reject(node, "operator not allowed")
            self._check(node.left, allowed)
            self._check(node.right, allowed)
        elif isinstance(node, ast.UnaryOp):
            if type(node.op) not in _UNARY:
                raise self._reject(node, "operator not allowed")
            self._check(node.operand, allowed)
        elif isinstance(node, ast.BoolOp):
            for v in node.values:
                self._check(v, allowed)
        elif isinstance(node, ast.Compare):
            if not all(isinstance(op, _COMPARE) for op in node.ops):
                raise self._reject(node, "only ==, !=, <, <=, >, >= comparisons are allowed")
            self._check(node.left, allowed)
            for c in node.comparators:
                self._check(c, allowed)
        elif isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS:
                raise self._reject(node.func, f"only these functions may be called: {', '.join(sorted(FUNCTIONS))}")
            if node.keywords:
                raise self._reject(node, "keyword arguments are not allowed")
            for a in node.args:
                if isinstance(a, ast.Starred):
                    raise self._reject(a, "starred arguments are not allowed")
                self._check(a, allowed)
            n = ARITY[node.func.id]
            if len(node.args) != n:
                raise self._reject(node, f"{node.func.id} takes {n} argument{'s' if n > 1 else ''}, "
                                         f"not {len(node.args)}")
        else:
            raise self._reject(node, f"{type(node).__name__} is not allowed, only arithmetic")

    # -- evaluation -------------------------------------------------------------------------------
    def evaluate(self, values: Mapping[str, Any], eq_tol: float = 0.0) -> Any:
        """Value of the expression; comparisons hold or fail by more than ``eq_tol`` (absolute)."""
        env = dict(CONSTANTS)
        env.update(values)
        with np.errstate(all="ignore"):
            try:
                return self._eval(self._tree, env, eq_tol)
            except RecursionError:  # checked trees just under the limit can still exceed it here
                raise ProblemError(f"expression {_short(self.text)!r} is nested too deeply") from None

    def _eval(self, node: ast.AST, env: Mapping[str, Any], tol: float) -> Any:
        if isinstance(node, ast.Constant):
            return np.float64(node.value)
        if isinstance(node, ast.Name):
            if node.id not in env:
                raise self._reject(node, f"no value for {node.id!r} here")
            return env[node.id]
        if isinstance(node, ast.BinOp):
            return _BINOPS[type(node.op)](self._eval(node.left, env, tol), self._eval(node.right, env, tol))
        if isinstance(node, ast.UnaryOp):
            return _UNARY[type(node.op)](self._eval(node.operand, env, tol))
        if isinstance(node, ast.BoolOp):
            combine = np.logical_and if isinstance(node.op, ast.And) else np.logical_or
            out = self._eval(node.values[0], env, tol)
            for v in node.values[1:]:
                out = combine(out, self._eval(v, env, tol))
            return out
        if isinstance(node, ast.Compare):
            left = self._eval(node.left, env, tol)
            out = True
            for op, comp in zip(node.ops, node.comparators):
                right = self._eval(comp, env, tol)
                out = np.logical_and(out, _compare(op, left, right, tol))
                left = right
            return out
        if isinstance(node, ast.Call):
            args = [self._eval(a, env, tol) for a in node.args]
            try:
                return FUNCTIONS[node.func.id](*args)
            except (TypeError, ValueError) as exc:
                raise self._reject(node, f"bad call ({exc})") from None
        raise AssertionError("unchecked node")  # _check admits nothing else


def _short(text: str, limit: int = 60) -> str:
    """The expression for a message, cut short: a pathological one may be megabytes long."""
    return text if len(text) <= limit else text[:limit] + "..."


def _compare(op: ast.cmpop, a: Any, b: Any, tol: float) -> Any:
    # every comparison tests the one rounded difference a - b, so that `a == b` is exactly
    # `a <= b and a >= b` and `a < b` exactly `not a >= b` (comparing a with b - tol rounds differently)
    d = np.subtract(a, b)
    if isinstance(op, ast.Eq):
        return np.abs(d) <= tol
    if isinstance(op, ast.NotEq):
        return np.abs(d) > tol
    # inequalities honour the tolerance too: `x >= L` keeps a node at L - 1e-15, `x > 0` drops one at 1e-15
    if isinstance(op, ast.Lt):
        return d < -tol
    if isinstance(op, ast.LtE):
        return d <= tol
    if isinstance(op, ast.Gt):
        return d > tol
    return d >= -tol


def constant(text: str | float | int, parameters: Mapping[str, float]) -> float:
    """A number, or an expression of the parameters only (no x, y), as a float."""
    expr = Expression(text, allowed=set(parameters))
    value = float(expr.evaluate(parameters))
    if not math.isfinite(value):
        raise ProblemError(f"expression {expr.text!r} is not a finite number ({value})")
    return value


class Field:
    """An expression of x, y (and t) and the parameters, evaluated pointwise over arrays."""

    def __init__(self, text: str | float | int, parameters: Mapping[str, float]) -> None:
        self.expr = Expression(text, allowed=set(parameters) | set(VARIABLES))
        self.parameters = dict(parameters)

    @property
    def text(self) -> str:
        """The expression's source text."""
        return self.expr.text

    def __call__(self, x: np.ndarray, y: np.ndarray, t: float = 0.0, eq_tol: float = 0.0) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        out = self.expr.evaluate({**self.parameters, "x": x, "y": y, "t": t}, eq_tol=eq_tol)
        return np.broadcast_to(np.asarray(out), np.broadcast_shapes(x.shape, y.shape)).copy()
