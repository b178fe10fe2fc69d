"""Every method's options are a checked contract (`METHODS`), the same from
Python and from a study file: unknown options and a second rule for a method
bound to one are one-line errors before any work."""

import numpy as np
import pytest

from spiralid.optim import RULES
from spiralid.study import parse_spec
from spiralid.sysid import ARX, METHODS, IOData, identify


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(0)
    u = rng.standard_normal(300)
    return IOData(u, np.convolve(u, [0.0, 1.0, 0.5])[:300], ts=0.01)


@pytest.mark.parametrize("method", list(METHODS))
def test_an_unknown_option_is_refused_by_every_method(record, method):
    with pytest.raises(ValueError, match="bogus") as info:
        identify(record, ARX(2, 2, 1), method=method, bogus=1)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("rule", list(RULES))
def test_a_rule_method_cannot_be_re_ruled(record, rule):
    other = next(r for r in RULES if r != rule)
    with pytest.raises(ValueError, match=f"`rule` does not apply to method '{rule}'"):
        identify(record, ARX(2, 2, 1), method=rule, rule=other, rng=0)


def test_the_options_a_rule_method_accepts_still_work(record):
    fit = identify(record, ARX(2, 2, 1), method="sda", rng=0, n_points=8,
                   max_nfev=100, bounds_policy="clip")  # fmt: skip
    assert fit.method == "sda" and fit.result["nfev"] <= 100


SPEC = """
[study]
seeds = 1
budget = 1000
[grid]
predictors = ["simulation-rest"]
parametrizations = ["coefficients"]
[[data]]
name = "rig"
kind = "rig"
[[optimizer]]
method = "{method}"
options = {{ {options} }}
"""


@pytest.mark.parametrize(
    "method, options, words",
    [
        ("sda", 'rule = "ebsda"', "`rule` does not apply to method 'sda'"),
        ("ebsda", "bogus = 1", "`bogus` does not apply to method 'ebsda'"),
        (
            "de",
            "bounds_policy = 'clip'",
            "`bounds_policy` does not apply to method 'de'",
        ),
    ],
)
def test_a_study_file_is_checked_before_any_run(method, options, words):
    with pytest.raises(ValueError) as info:
        parse_spec(SPEC.format(method=method, options=options), where="s.toml")
    assert words in str(info.value) and "\n" not in str(info.value)


def test_method_names_in_any_case_as_minimize_takes_them(record):
    from spiralid.optim import minimize

    upper = identify(record, ARX(2, 2, 1), method="EbSDA", rng=0, max_nfev=200)
    lower = identify(record, ARX(2, 2, 1), method="ebsda", rng=0, max_nfev=200)
    assert upper.method == "ebsda" and np.array_equal(upper.theta, lower.theta)
    box = [(-1.0, 1.0)] * 2
    assert minimize(lambda x: x @ x, box, "EBSDA", rng=0, max_iter=3).nit == 3
