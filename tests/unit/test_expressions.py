"""Problem-file expressions: arithmetic over arrays, tolerant comparisons, and the whitelist."""
from __future__ import annotations

import math
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ctmrpim.errors import ProblemError
from ctmrpim.problem.expressions import Expression, Field, constant

X = np.array([-2.0, -0.5, 0.0, 0.25, 1.0, 3.0])
Y = np.array([1.0, 2.0, -1.0, 0.5, -3.0, 0.75])


def ev(text: str, tol: float = 0.0, **values) -> np.ndarray:
    return Expression(text, allowed=set(values) | {"x", "y", "t"}).evaluate({"x": X, "y": Y, **values}, eq_tol=tol)


@pytest.mark.parametrize("text, expected", [
    ("x + 2*y - 3", X + 2 * Y - 3),
    ("x**2 - y / 4", X**2 - Y / 4),
    ("-x % 2", np.mod(-X, 2)),
    ("+x * (y - 1)", X * (Y - 1)),
    ("2**3**2", np.full_like(X, 512.0)),  # right-associative, as in Python
    ("sin(pi*x) + cos(y)", np.sin(np.pi * X) + np.cos(Y)),
    ("sqrt(abs(x)) * exp(-y)", np.sqrt(np.abs(X)) * np.exp(-Y)),
    ("hypot(x, y)", np.hypot(X, Y)),
    ("atan2(y, x) + arctan2(x, y)", np.arctan2(Y, X) + np.arctan2(X, Y)),
    ("min(x, y) + max(x, y)", X + Y),
    ("where(x > 0, x, -y)", np.where(X > 0, X, -Y)),
    ("log(e) + log10(100) + floor(x) + ceil(y) + sign(x)", 3 + np.floor(X) + np.ceil(Y) + np.sign(X)),
    ("degrees(radians(x))", X),
    ("tanh(x) + sinh(y) - cosh(x) + tan(y/4)", np.tanh(X) + np.sinh(Y) - np.cosh(X) + np.tan(Y / 4)),
])
def test_arithmetic_over_arrays(text: str, expected: np.ndarray) -> None:
    np.testing.assert_allclose(np.broadcast_to(ev(text), X.shape), expected, rtol=1e-14, atol=1e-14)


def test_parameters_and_constants() -> None:
    assert constant("W**3 / 12", {"W": 12.0}) == 144.0
    assert constant(7, {}) == 7.0 and constant(2.5, {}) == 2.5
    assert constant("2*pi", {}) == pytest.approx(2 * math.pi, rel=1e-15)
    f = Field("P/(2*I) * (W**2/4 - y**2)", {"P": -1000.0, "I": 144.0, "W": 12.0})
    np.testing.assert_allclose(f(X, Y), -1000.0 / 288.0 * (36.0 - Y**2), rtol=1e-15)
    assert f.expr.names == {"P", "I", "W", "y"}
    # a constant field still has the shape of its points
    assert Field("3", {})(X, Y).shape == X.shape
    assert Field("t", {})(X, Y, t=2.0).tolist() == [2.0] * len(X)


def test_equality_matches_within_tolerance() -> None:
    x = np.array([1.0 - 2e-3, 1.0 - 5e-4, 1.0, 1.0 + 5e-4, 1.0 + 2e-3])
    e = Expression("x == 1")
    assert e.evaluate({"x": x}).tolist() == [False, False, True, False, False]
    assert e.evaluate({"x": x}, eq_tol=1e-3).tolist() == [False, True, True, True, False]
    assert Expression("x != 1").evaluate({"x": x}, eq_tol=1e-3).tolist() == [True, False, False, False, True]


def test_inequalities_honour_the_tolerance() -> None:
    """Strict comparisons exclude the tolerance band, non-strict ones include it, so that `x >= L`
    keeps a node at L - 1e-15 and `x > 0` drops one at 1e-15; `a < b` stays `not (a >= b)`."""
    x = np.array([1.0 - 2e-3, 1.0 - 5e-4, 1.0, 1.0 + 5e-4, 1.0 + 2e-3])
    tol = 1e-3
    cases = {"x < 1": [True, False, False, False, False], "x <= 1": [True, True, True, True, False],
             "x > 1": [False, False, False, False, True], "x >= 1": [False, True, True, True, True]}
    for text, expected in cases.items():
        assert Expression(text).evaluate({"x": x}, eq_tol=tol).tolist() == expected, text
    # without tolerance they are the ordinary comparisons
    plain = {"x < 1": x < 1, "x <= 1": x <= 1, "x > 1": x > 1, "x >= 1": x >= 1}
    for text, expected in plain.items():
        assert Expression(text).evaluate({"x": x}).tolist() == expected.tolist(), text


@settings(max_examples=200, deadline=None)
@given(a=st.floats(-10, 10), b=st.floats(-10, 10), tol=st.floats(0, 1))
def test_comparisons_are_complementary(a: float, b: float, tol: float) -> None:
    v = {"a": a, "b": b}
    def holds(text: str) -> bool:
        return bool(Expression(text, allowed={"a", "b"}).evaluate(v, eq_tol=tol))
    assert holds("a < b") != holds("a >= b")
    assert holds("a > b") != holds("a <= b")
    assert holds("a == b") != holds("a != b")
    assert holds("a == b") == (holds("a <= b") and holds("a >= b"))


def test_chained_comparison_and_boolean_operators() -> None:
    np.testing.assert_array_equal(ev("-1 <= x <= 1"), (X >= -1) & (X <= 1))
    np.testing.assert_array_equal(ev("x > 0 and y > 0"), (X > 0) & (Y > 0))
    np.testing.assert_array_equal(ev("x > 0 or y > 0"), (X > 0) | (Y > 0))
    np.testing.assert_array_equal(ev("not x > 0"), ~(X > 0))
    np.testing.assert_array_equal(ev("x == 0 or x == 3 and y > 0"), (X == 0) | ((X == 3) & (Y > 0)))
    np.testing.assert_array_equal(ev("hypot(x, y) == 2 and y > 0", tol=0.1),
                                  (np.abs(np.hypot(X, Y) - 2) <= 0.1) & (Y > 0.1))


@pytest.mark.parametrize("text, part", [
    ("().__class__", "().__class__"),
    ("x.real", "x.real"),
    ("x[0]", "x[0]"),
    ("(lambda: 1)()", "lambda: 1"),
    ("[v for v in (1, 2)]", "[v for v in (1, 2)]"),
    ("sum(v for v in (1, 2))", "sum"),
    ("hypot(x, y=1)", "hypot(x, y=1)"),
    ("hypot(*x)", "*x"),
    ("foo * x", "foo"),
    ("open('x')", "open"),
    ("__import__('os')", "__import__"),
    ("__import__('os').system('touch HACKED')", "__import__('os').system"),
    ("eval('1')", "eval"),
    ("'abc'", "'abc'"),
    ("x + 'abc'", "'abc'"),
    ("True", "True"),
    ("x == False", "False"),
    ("1j", "1j"),
    ("x if y else 1", "x if y else 1"),
    ("x // 2", "x // 2"),
    ("x @ y", "x @ y"),
    ("~x", "~x"),
    ("x in y", "x in y"),
    ("x is y", "x is y"),
    ("(z := 1)", "z := 1"),
    ("{1: 2}", "{1: 2}"),
    ("sin", "sin"),
    ("sin(x, y)", "sin(x, y)"),   # a second positional argument of a ufunc is its `out` array
    ("where(x > 0)", "where(x > 0)"),
])
def test_rejected_with_the_expression_and_the_offending_part(text: str, part: str) -> None:
    with pytest.raises(ProblemError) as info:
        Field(text, {})
    msg = str(info.value)
    assert repr(text) in msg, msg
    assert repr(part) in msg, msg


def test_rejection_reasons() -> None:
    with pytest.raises(ProblemError, match="unknown name 'foo'"):
        Field("foo*x", {})
    with pytest.raises(ProblemError, match="keyword arguments are not allowed"):
        Field("hypot(x, y=1)", {})
    with pytest.raises(ProblemError, match="only these functions may be called"):
        Field("open('x')", {})
    with pytest.raises(ProblemError, match="only numbers are allowed as constants"):
        Field("True", {})
    with pytest.raises(ProblemError, match="not valid arithmetic"):
        Field("x +", {})
    with pytest.raises(ProblemError, match="expected a number or an expression string"):
        Field(True, {})
    with pytest.raises(ProblemError, match="expected a number or an expression string"):
        Field([1, 2], {})
    # x and y are not known in a constant (geometry, material, method values)
    with pytest.raises(ProblemError, match="unknown name 'x'"):
        constant("2*x", {"L": 1.0})
    with pytest.raises(ProblemError, match="not a finite number"):
        constant("1/0", {})


def test_nothing_runs(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ProblemError):
        Field("__import__('os').system('touch HACKED')", {})
    assert not (tmp_path / "HACKED").exists()


def test_big_powers_and_deep_nesting_do_not_hang() -> None:
    t0 = time.perf_counter()
    assert Expression("9**9**9").evaluate({}) == np.inf       # float arithmetic, never a huge integer
    assert np.isposinf(Field("9**9**9 + x", {})(X, Y)).all()
    with pytest.raises(ProblemError, match="not a finite number"):
        constant("9**9**9", {})
    with pytest.raises(ProblemError, match="nested too deeply"):
        Expression("-" * 100_000 + "1")
    with pytest.raises(ProblemError, match="nested too deeply"):
        Expression("+".join(["1"] * 100_000))
    assert time.perf_counter() - t0 < 5.0


# -- property: random expressions from a small grammar agree with the same numpy arithmetic ---------
LEAVES = st.sampled_from(["x", "y", "a", "1.5", "2", "0.25"])


def _combine(children):
    binary = st.tuples(st.sampled_from(["+", "-", "*", "/"]), children, children).map(
        lambda t: (f"({t[1][0]} {t[0]} {t[2][0]})", {"+": np.add, "-": np.subtract, "*": np.multiply,
                                                       "/": np.divide}[t[0]], (t[1], t[2])))
    unary = st.tuples(st.sampled_from(["-", "sin", "cos", "abs", "exp"]), children).map(
        lambda t: (f"(-{t[1][0]})" if t[0] == "-" else f"{t[0]}({t[1][0]})",
                   {"-": np.negative, "sin": np.sin, "cos": np.cos, "abs": np.abs, "exp": np.exp}[t[0]],
                   (t[1],)))
    return binary | unary


TREES = st.recursive(LEAVES.map(lambda s: (s, None, ())), _combine, max_leaves=12)


def _numpy(tree, env) -> np.ndarray:
    text, op, kids = tree
    if op is None:
        return env[text] if text in env else np.float64(text)
    return op(*(_numpy(k, env) for k in kids))


@settings(max_examples=300, deadline=None)
@given(tree=TREES, a=st.floats(-3, 3, allow_subnormal=False))
def test_random_expressions_match_numpy(tree, a: float) -> None:
    env = {"x": X, "y": Y, "a": a}
    with np.errstate(all="ignore"):
        expected = np.broadcast_to(_numpy(tree, env), X.shape)
    got = Field(tree[0], {"a": a})(X, Y)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=0, equal_nan=True)
