"""A problem file's expressions as UFL: the text the user wrote, parsed again and translated node by node.

ctmrpim evaluates its expressions with numpy (``ctmrpim.problem.expressions``); here the same text becomes a
UFL expression of the spatial coordinate, so loads, prescribed displacements, the exact solution and the
``where`` selectors reach dolfinx without any value computed by ctmrpim. The text has already been checked
by ctmrpim's whitelist; what UFL cannot express (``floor``, ``ceil``, ``%``) is refused by name.

Comparisons follow ctmrpim's rule: each tests the one difference ``d = a - b`` against a tolerance
(``==``: ``|d| <= tol``, ``<``: ``d < -tol``, ``>=``: ``d >= -tol`` ...), zero for fields and the match
tolerance for selectors.
"""
from __future__ import annotations

import ast
import math

import ufl
from ufl.classes import Condition


class TranslationError(ValueError):
    """An expression UFL cannot express (the message names the part)."""


def _number(v):
    """A value usable in arithmetic: a condition becomes 1 or 0 (numpy's True * 2 = 2)."""
    return ufl.conditional(v, 1.0, 0.0) if isinstance(v, Condition) else v


def _truth(v):
    """A condition: numbers are true where non-zero (numpy's ``where(a, ...)``)."""
    return v if isinstance(v, Condition) else ufl.ne(v, 0.0)


def _hypot(a, b):
    return ufl.sqrt(a * a + b * b)


#: the functions of ctmrpim's whitelist that UFL has
FUNCTIONS = {
    "sin": ufl.sin, "cos": ufl.cos, "tan": ufl.tan,
    "asin": ufl.asin, "acos": ufl.acos, "atan": ufl.atan, "atan2": ufl.atan_2,
    "arcsin": ufl.asin, "arccos": ufl.acos, "arctan": ufl.atan, "arctan2": ufl.atan_2,
    "sinh": ufl.sinh, "cosh": ufl.cosh, "tanh": ufl.tanh,
    "exp": ufl.exp, "log": ufl.ln, "log10": lambda a: ufl.ln(a) / math.log(10.0), "sqrt": ufl.sqrt,
    "abs": abs, "hypot": _hypot, "min": ufl.min_value, "max": ufl.max_value, "sign": ufl.sign,
    "where": lambda c, a, b: ufl.conditional(_truth(c), _number(a), _number(b)),
    "radians": lambda a: a * (math.pi / 180.0), "degrees": lambda a: a * (180.0 / math.pi),
}
#: the same functions on plain numbers (a subexpression without x, y or parameters)
NUMBERS = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos, "atan": math.atan,
    "atan2": math.atan2, "arcsin": math.asin, "arccos": math.acos, "arctan": math.atan, "arctan2": math.atan2,
    "sinh": math.sinh, "cosh": math.cosh, "tanh": math.tanh, "exp": math.exp, "log": math.log,
    "log10": math.log10, "sqrt": math.sqrt, "abs": abs, "hypot": math.hypot, "min": min, "max": max,
    "sign": lambda a: float((a > 0) - (a < 0)), "where": lambda c, a, b: a if c else b,
    "radians": math.radians, "degrees": math.degrees,
}
CONSTANTS = {"pi": math.pi, "e": math.e}


class Translator:
    """Expressions of x, y (t = 0: static analyses) and named parameters as UFL, given the coordinate ``X``
    (``ufl.SpatialCoordinate``) and the parameters as UFL values (dolfinx Constants, so that a change of
    a parameter's value reuses the compiled forms)."""

    def __init__(self, X, parameters: dict) -> None:
        self.names = {"x": X[0], "y": X[1], "t": 0.0, **CONSTANTS, **parameters}

    def __call__(self, text: str, tol=0.0):
        """UFL value of ``text``; comparisons hold or fail by more than ``tol``."""
        self.text, self.tol = text, tol
        return self._walk(ast.parse(text.strip(), mode="eval").body)

    def _refuse(self, node, why: str) -> TranslationError:
        part = ast.get_source_segment(self.text.strip(), node) or type(node).__name__
        return TranslationError(f"expression {self.text!r}: {why} ({part!r}), which the FEniCSx bridge cannot "
                                "translate to UFL")

    def _walk(self, node):
        if isinstance(node, ast.Constant):
            return float(node.value)
        if isinstance(node, ast.Name):
            if node.id not in self.names:
                raise self._refuse(node, f"unknown name {node.id!r}")
            return self.names[node.id]
        if isinstance(node, ast.UnaryOp):
            v = self._walk(node.operand)
            if isinstance(node.op, ast.Not):
                return (not v) if isinstance(v, float) else ufl.Not(_truth(v))
            return -_number(v) if isinstance(node.op, ast.USub) else _number(v)
        if isinstance(node, ast.BinOp):
            return self._binary(node)
        if isinstance(node, ast.BoolOp):
            values = [self._walk(v) for v in node.values]
            join = ufl.And if isinstance(node.op, ast.And) else ufl.Or
            out = _truth(values[0])
            for v in values[1:]:
                out = join(out, _truth(v))
            return out
        if isinstance(node, ast.Compare):
            left, out = self._walk(node.left), None
            for op, comp in zip(node.ops, node.comparators):
                right = self._walk(comp)
                c = self._compare(op, _number(left) - _number(right))
                out = c if out is None else ufl.And(out, c)
                left = right
            return out
        if isinstance(node, ast.Call):
            name = node.func.id
            args = [self._walk(a) for a in node.args]
            if name not in FUNCTIONS:
                raise self._refuse(node, f"function {name!r}")
            if all(isinstance(a, float) for a in args):
                return float(NUMBERS[name](*args))
            return FUNCTIONS[name](*[a if name == "where" else _number(a) for a in args])
        raise self._refuse(node, f"{type(node).__name__}")

    def _binary(self, node):
        a, b = _number(self._walk(node.left)), _number(self._walk(node.right))
        op = node.op
        if isinstance(op, ast.Mod):
            raise self._refuse(node, "the operator %")
        if isinstance(op, ast.Add):
            return a + b
        if isinstance(op, ast.Sub):
            return a - b
        if isinstance(op, ast.Mult):
            return a * b
        if isinstance(op, ast.Div):
            return a / b
        if isinstance(op, ast.Pow):
            return a ** b
        raise self._refuse(node, "operator")

    def _compare(self, op, d):
        tol = self.tol
        if isinstance(op, ast.Eq):
            return ufl.le(abs(d), tol)
        if isinstance(op, ast.NotEq):
            return ufl.gt(abs(d), tol)
        if isinstance(op, ast.Lt):
            return ufl.lt(d, -tol)
        if isinstance(op, ast.LtE):
            return ufl.le(d, tol)
        if isinstance(op, ast.Gt):
            return ufl.gt(d, tol)
        return ufl.ge(d, -tol)
