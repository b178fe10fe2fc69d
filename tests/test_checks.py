"""The shared choice check, `spiralid._checks.one_of`, and the public calls
that use it: the choices are listed, and a non-string (an unhashable list
included) is refused as a wrong choice, not a TypeError from a dict."""

import pytest

from spiralid._checks import one_of
from spiralid.datasets import load
from spiralid.optim import LearnedMetricSpiral


def test_a_choice_is_returned_as_given():
    assert one_of("b", "kind", ("a", "b")) == "b"
    assert one_of("y", "key", {"x": 1, "y": 2}) == "y"


@pytest.mark.parametrize("value", ["c", "A", 1, None, ["a"], b"a"])
def test_anything_else_is_refused_with_the_choices_listed(value):
    message = rf"^`kind` must be one of \('a', 'b'\); got {value!r}$"
    with pytest.raises(ValueError, match=message.replace("[", r"\[")):
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
    with pytest.raises(ValueError, match=rf"^`{name}` must be one of \("):
        call()
