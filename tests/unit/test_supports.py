"""Supports checked before a static solve (ctmrpim.problem.supports): the rigid motions constraints leave
free, named; conflicting prescribed values; loads that act only on prescribed displacements."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from ctmrpim import benchmarks
from ctmrpim.errors import ProblemError
from ctmrpim.problem import supports


@pytest.fixture(scope="module")
def beam():
    """The cantilever's rectangle, 0 <= x <= 48, -6 <= y <= 6."""
    return benchmarks.load("cantilever").problem


def free(problem, positions, components) -> str | None:
    try:
        supports.check_rigid_motion(problem, np.asarray(positions, float), np.asarray(components), 1e-9)
    except ProblemError as exc:
        return str(exc)
    return None


def test_a_clamped_edge_holds_the_body(beam) -> None:
    y = np.linspace(-6, 6, 5)
    at = np.c_[np.zeros(10), np.r_[y, y]]
    assert free(beam, at, np.r_[np.zeros(5, int), np.ones(5, int)]) is None


def test_a_pin_and_a_roller_hold_the_body(beam) -> None:
    # pin at (0, 0), vertical roller at (48, 0): the classic simply supported beam
    assert free(beam, [[0, 0], [0, 0], [48, 0]], [0, 1, 1]) is None


@pytest.mark.parametrize("positions, components, motion", [
    ([[0, 0], [0, 0]], [0, 1], "free to rotate about (0, 0)"),                       # one pin
    ([[10, -6], [10, -6]], [0, 1], "free to rotate about (10, -6)"),
    ([[0, -6], [0, 0], [0, 6]], [0, 0, 0], "free to translate in y"),                # ux on an edge only
    ([[0, -6], [24, -6], [48, -6]], [1, 1, 1], "free to translate in x"),            # uy on the base only
    ([[0, 0], [0, 0], [48, 0]], [0, 1, 0], "free to rotate about (0, 0)"),           # roller along the pin's line
    ([[0, 2], [0, 2]], [0, 0], "free to translate in y and to rotate"),               # one component at one node
    ([], [], "free to translate in x and y and to rotate (no constrained node)"),
])
def test_the_free_motion_is_named(beam, positions, components, motion) -> None:
    message = free(beam, np.reshape(positions, (-1, 2)), components)
    assert message is not None and motion in message and "the body" in message


def test_uy_held_on_one_vertical_line_leaves_x_and_a_rotation_about_it(beam) -> None:
    message = free(beam, [[0, -6], [0, 6]], [1, 1])
    assert "free to translate in x and to rotate" in message


def test_each_part_must_be_held() -> None:
    case = benchmarks.load("cantilever", ['geometry.add=[{rectangle = [0, -6, 48, 6]}, {rectangle = [60, -6, 70, 6]}]'])
    y = np.linspace(-6, 6, 5)
    at = np.c_[np.zeros(10), np.r_[y, y]]
    message = free(case.problem, at, np.r_[np.zeros(5, int), np.ones(5, int)])
    assert "part 2 of the body, within (60, -6) .. (70, 6)" in message and "no constrained node" in message


def test_explicit_dynamics_may_fly_freely(beam) -> None:
    assert free(dataclasses.replace(beam, analysis="explicit"), [[0, 0]], [0]) is None


def prescribed(i, dofs, values, comp=0):
    dofs = np.asarray(dofs)
    return supports.Prescribed(i, dofs, np.c_[dofs, 0 * dofs].astype(float), np.full(len(dofs), comp),
                               np.asarray(values, float))


def test_equal_values_merge_and_different_ones_are_refused() -> None:
    dofs, values, _, _ = supports.merge([prescribed(0, [0, 2, 4], [0, 0, 0]), prescribed(1, [4, 6], [0, 1])])
    assert dofs.tolist() == [0, 2, 4, 6] and values.tolist() == [0, 0, 0, 1]
    with pytest.raises(ProblemError, match=r"constraint\[1\] prescribes ux = 0.5 at \(4, 0\), where constraint\[0\] "
                                           r"prescribes ux = 0: the two disagree"):
        supports.merge([prescribed(0, [0, 2, 4], [0, 0, 0]), prescribed(1, [4, 6], [0.5, 1])])


def test_a_load_on_prescribed_displacements_is_refused() -> None:
    case = benchmarks.load("cantilever")
    y = np.linspace(-6, 6, 5)
    x_left, x_right = np.zeros(5), np.full(5, 48.0)
    supports.check_loads_on_supports(case.problem, np.r_[x_left, x_right], np.r_[y, y], 1e-6)   # the benchmark: fine
    moved = dataclasses.replace(case.problem, tractions=[dataclasses.replace(case.problem.tractions[0],
                                                                             where=case.problem.constraints[0].where)])
    with pytest.raises(ProblemError, match="ty acts only where a constraint prescribes"):
        supports.check_loads_on_supports(moved, np.r_[x_left, x_right], np.r_[y, y], 1e-6)
