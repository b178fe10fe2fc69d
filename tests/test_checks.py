"""The shared argument checks of `spiralid._checks` and the public calls
that use them: the choices are listed, and, as in SciPy, a value of the
wrong type (a non-string choice, an unhashable list included) is a
TypeError and a value of the right type out of range a ValueError, both
naming the argument."""

import pytest

from spiralid._checks import (
    box_bounds,
    generator,
    integer,
    named_index,
    nonneg,
    one_of,
    positive,
    real,
    real_array,
)
from spiralid.datasets import load
from spiralid.fms import FlexibleManipulator, Sensors
from spiralid.optim import LearnedMetricSpiral, minimize


def test_a_choice_is_returned_as_given():
    assert one_of("b", "kind", ("a", "b")) == "b"
    assert one_of("y", "key", {"x": 1, "y": 2}) == "y"


@pytest.mark.parametrize(
    ("value", "error"),
    [
        ("c", ValueError),
        ("A", ValueError),
        (1, TypeError),
        (None, TypeError),
        (["a"], TypeError),
        (b"a", TypeError),
    ],
)
def test_anything_else_is_refused_with_the_choices_listed(value, error):
    message = rf"^`kind` must be one of \('a', 'b'\); got {value!r}$"
    with pytest.raises(error, match=message.replace("[", r"\[")):
        one_of(value, "kind", ("a", "b"))


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: load(["robot_arm"]), "name"),
        (lambda: LearnedMetricSpiral(basis_gap=10), "basis_gap"),
        (lambda: LearnedMetricSpiral(sampling=["gaussian"]), "sampling"),
    ],
)
def test_public_calls_name_the_argument(call, name):
    with pytest.raises(TypeError, match=rf"^`{name}` must be one of \("):
        call()


def _sphere(x):
    return float(x @ x)


@pytest.mark.parametrize(
    ("call", "error", "name"),
    [
        (lambda: real("1.5", "x"), TypeError, "x"),
        (lambda: real([1.0], "x"), TypeError, "x"),
        (lambda: real(float("nan"), "x"), ValueError, "x"),
        (lambda: positive(True, "x"), TypeError, "x"),
        (lambda: positive(-1.0, "x"), ValueError, "x"),
        (lambda: nonneg(None, "x"), TypeError, "x"),
        (lambda: nonneg(-1, "x"), ValueError, "x"),
        (lambda: integer(2.0, "k", 1), TypeError, "k"),
        (lambda: integer("2", "k", 1), TypeError, "k"),
        (lambda: integer(0, "k", 1), ValueError, "k"),
        (lambda: named_index(1.0, "output", ("a", "b")), TypeError, "output"),
        (lambda: named_index(2, "output", ("a", "b")), ValueError, "output"),
        (lambda: real_array("ab", "u"), TypeError, "u"),
        (lambda: real_array([1j], "u"), TypeError, "u"),
        (lambda: real_array([[1.0], [2.0, 3.0]], "u"), ValueError, "u"),
        (lambda: generator(1.5), TypeError, "rng"),
        (lambda: generator(-1), ValueError, "rng"),
        (lambda: box_bounds("ab"), TypeError, "bounds"),
        (lambda: box_bounds(None), TypeError, "bounds"),
        (lambda: box_bounds([(1, 0)]), ValueError, "bounds"),
        (lambda: minimize(_sphere, [(0, 1)], n_points=10.0), TypeError, "n_points"),
        (lambda: minimize(_sphere, [(0, 1)], n_points=1), ValueError, "n_points"),
        (lambda: minimize(_sphere, [(0, 1)], method=3), TypeError, "method"),
        (lambda: minimize(_sphere, [(0, 1)], method="pso"), ValueError, "method"),
        (lambda: minimize(_sphere, [(0, 1)], callback=3), TypeError, "callback"),
        (lambda: minimize(_sphere, [(0, 1)], options=[]), TypeError, "options"),
        (lambda: FlexibleManipulator(length="a"), TypeError, "length"),
        (lambda: FlexibleManipulator(length=-1.0), ValueError, "length"),
        (lambda: FlexibleManipulator(damping_ratio="a"), TypeError, "damping_ratio"),
        (lambda: FlexibleManipulator(damping_ratio=1.0), ValueError, "damping_ratio"),
        (lambda: Sensors(antialias_order=2.0), TypeError, "antialias_order"),
        (lambda: Sensors(antialias_order=13), ValueError, "antialias_order"),
    ],
)
def test_a_wrong_type_is_a_type_error_and_a_wrong_value_a_value_error(
    call, error, name
):
    with pytest.raises((TypeError, ValueError)) as refused:
        call()
    assert refused.type is error
    assert str(refused.value).startswith(f"`{name}` ")


def test_the_command_line_reports_a_type_error_of_our_checks_as_the_user_s():
    from spiralid.cli.errors import is_user_error

    with pytest.raises(TypeError) as ours:
        integer("2", "k", 1)
    assert is_user_error(ours.value)
    with pytest.raises(TypeError) as pythons:
        integer()  # a bug: Python's own TypeError names no argument in backticks
    assert not is_user_error(pythons.value)
