"""The estimator design: one table of methods, parametrisation objects, one
result type, one budget rule, the safe start and capped polishes."""

from functools import partial

import numpy as np
import pytest
from scipy import optimize, signal

from spiralid.cli import build_parser
from spiralid.datasets import robot_arm
from spiralid.sysid import ARX, IOData, PaperCost, identify, step_up
from spiralid.sysid.estimation.core import estimators
from spiralid.sysid.estimation.core.estimators import (
    METHODS,
    STATUS,
    EstimatorResult,
    search_options,
)
from spiralid.sysid.estimation.linear import (
    local_estimators,
    outputerror,
    parametrizations,
)
from spiralid.sysid.estimation.linear.parametrizations import (
    PARAMETRIZATIONS,
    stabilise,
)

SEARCHES = [name for name, m in METHODS.items() if m.search]


@pytest.fixture(scope="module")
def record():
    """Two lightly damped modes, output noise: least squares is good, a
    short spiral search is not."""
    rng = np.random.default_rng(5)
    u = rng.standard_normal(500)
    poles = [0.95 * np.exp(0.4j), 0.9 * np.exp(1.2j)]
    a = np.real(np.poly([*poles, *np.conj(poles)]))
    y = signal.lfilter([0.0, 0.5, -0.2, 0.1], a, u)
    return IOData(u, y + 0.05 * rng.standard_normal(u.size), ts=0.01)


ARX4 = ARX(4, 4, 1)


@pytest.mark.parametrize("method", list(METHODS))
def test_every_method_returns_one_result_type_whose_x_is_theta(record, method):
    options = dict(rng=0, n_points=10, max_nfev=300) if METHODS[method].search else {}
    fit = identify(record, ARX4, method=method, **options)
    res = fit.result
    assert isinstance(res, EstimatorResult)
    assert isinstance(res, optimize.OptimizeResult)
    np.testing.assert_array_equal(res["x"], fit.theta)
    assert res["fun"] == fit.cost == PaperCost(ARX4, record)(fit.theta)
    assert res["status"] in STATUS and isinstance(res["message"], str)
    if METHODS[method].search:
        assert res["status"] == 1 and res["nfev"] <= 300  # the budget stopped it
        np.testing.assert_array_equal(res.history, fit.history)


def test_the_budget_rule_lifts_the_iteration_cap(record):
    # Without a budget the optimiser's own cap of 500 iterations holds...
    capped = identify(record, ARX4, method="sda", rng=1, n_points=3, max_iter=500)
    assert capped.result.nit == 500 and capped.result.status == 2
    # ...with one, the budget is the stop (2 evaluations per iteration here).
    budget = identify(record, ARX4, method="sda", rng=1, n_points=3, max_nfev=1500)
    assert budget.result.nit == (1500 - 3) // 2 and budget.result.status == 1
    assert search_options({"max_nfev": 7}) == {"max_nfev": 7, "max_iter": 7}
    assert search_options({"n_points": 9}) == {"n_points": 9}


def test_one_list_of_methods_and_parametrisations_in_the_cli():
    identify_cmd = build_parser()._subparsers._group_actions[0].choices["identify"]
    choices = {a.dest: a.choices for a in identify_cmd._actions if a.choices}
    # The parser takes the names from spiralid.choices (no estimator is
    # imported to build it); they are the tables' keys, in order.
    assert list(choices["method"]) == list(METHODS)
    assert list(choices["parametrization"]) == list(PARAMETRIZATIONS)
    assert identify_cmd.get_default("method") == estimators.DEFAULT_METHOD
    # The paper's methods keep their first population (and their numbers).
    assert not any(METHODS[m].safe_start for m in ("sda", "ebsda", "lasda", "de"))


class _Halved(parametrizations.Parametrization):
    """A test parametrisation: theta = 2 x (so the box is halved)."""

    name = "halved"

    def default_bounds(self):
        return parametrizations.Coefficients(self.data, self.arx).default_bounds() / 2

    def to_theta(self, x):
        return 2.0 * np.asarray(x, dtype=float)

    def from_theta(self, theta):
        return parametrizations.Coefficients(self.data, self.arx).from_theta(theta) / 2


def _estimate_zero(problem):
    """A test method: the zero model."""
    theta = np.zeros(problem.arx.n_params)
    return EstimatorResult(
        x=theta, fun=float(problem.cost(theta)), status=0, message="zero",
        nfev=1, nit=0, history=None, elapsed=0.0,
    )  # fmt: skip


def test_one_entry_adds_a_parametrisation_or_a_method(record, monkeypatch):
    monkeypatch.setitem(PARAMETRIZATIONS, "halved", _Halved)
    monkeypatch.setitem(
        METHODS, "zero", estimators.Method(_estimate_zero, search=False)
    )
    fit = identify(record, ARX4, method="sda", parametrization="halved", rng=2,
                   n_points=8, max_nfev=200)  # fmt: skip
    plain = identify(record, ARX4, method="sda", rng=2, n_points=8, max_nfev=200)
    np.testing.assert_array_equal(fit.bounds, plain.bounds / 2)
    np.testing.assert_array_equal(fit.theta, 2.0 * fit.result.x_search)
    assert fit.parametrization == "halved"
    assert identify(record, ARX4, method="zero").cost == pytest.approx(100.0)
    # The command line offers a name once it is also in spiralid.choices,
    # which each table is checked against at import.


def _stabilised_ls(data, arx):
    theta = identify(data, arx, method="ls").theta
    k_b = stabilise(theta, arx)
    return np.r_[step_up(k_b[: arx.na]), k_b[arx.na :]]


@pytest.mark.parametrize(
    "method, parametrization",
    [
        (m, p)
        for m in SEARCHES
        for p in PARAMETRIZATIONS
        # The recommended method searches the modes only.
        if m != "spiral" or p == "modal"
    ],
)
def test_no_safe_search_is_worse_than_the_zero_model_or_least_squares(
    record, method, parametrization
):
    # Against the costs of the two models computed here, not by the search.
    cost = PaperCost(ARX4, record)
    floor = min(cost(np.zeros(ARX4.n_params)), cost(_stabilised_ls(record, ARX4)))
    kw = dict(method=method, parametrization=parametrization, n_points=10)
    for seed in range(3):
        fit = identify(record, ARX4, rng=seed, max_nfev=100, safe_start=True, **kw)
        # The safe start enters the search through the parametrisation's
        # round trip (reflection coefficients and back), which may move the
        # last bits of its cost on another processor's BLAS.
        assert fit.cost <= floor * (1 + 1e-12)
        assert fit.result.safe_start
    if method == "spiral":
        # Its polish reaches below least squares without the safe start too,
        # so the check below cannot fail for it.
        return
    # The test can fail: without the safe start short searches end above
    # least squares on this record.
    plain = [
        identify(record, ARX4, rng=s, max_nfev=100, safe_start=False, **kw).cost
        for s in range(3)
    ]
    assert max(plain) > floor


def test_safe_refine_starts_from_the_search_ls_and_steiglitz_mcbride(record):
    oe = identify(record, ARX4, method="oe")
    fit = identify(record, ARX4, method="ebsda", rng=0, n_points=10, max_nfev=200,
                   refine=True, safe_start=True)  # fmt: skip
    assert set(fit.refine_result.starts) == {"search", "ls", "steiglitz-mcbride"}
    assert fit.refine_result.accepted
    # The output-error starts are among refine's, so it is never worse.
    assert fit.cost <= oe.cost
    assert fit.to_dict()["result"]["refine"]["start"] == fit.refine_result.start


def test_polish_says_when_it_stopped_at_its_evaluation_cap(record, monkeypatch):
    full = identify(record, ARX4, method="oe")
    assert full.result.status == 0
    monkeypatch.setattr(
        local_estimators,
        "local_polish",
        partial(outputerror.local_polish, max_nfev=3),
    )
    oe = identify(record, ARX4, method="oe")
    assert oe.result.status == 1 and oe.result.nfev <= 3
    assert "evaluation cap (max_nfev = 3)" in oe.result.message
    assert oe.cost > full.cost
    fit = identify(record, ARX4, method="sda", rng=0, n_points=10, max_nfev=100,
                   refine=True)  # fmt: skip
    assert fit.refine_result.status == 1
    saved = fit.to_dict()["result"]
    assert saved["refine"]["status"] == 1 and saved["status"] == 1


def test_bad_safe_start_is_rejected(record):
    with pytest.raises(TypeError, match="`safe_start` must be True, False or None"):
        identify(record, ARX4, method="sda", safe_start="yes")


@pytest.mark.parametrize("parametrization", list(PARAMETRIZATIONS))
@pytest.mark.parametrize("method", ["sda", "ebsda"])
def test_safe_searches_on_the_real_arm(method, parametrization):
    # The record where the paper's searches can end far above the zero model.
    data = robot_arm().split()[0]
    arx = ARX(8, 8, 0)
    cost = PaperCost(arx, data, initial="measured")
    floor = min(cost(np.zeros(arx.n_params)), cost(_stabilised_ls(data, arx)))
    if parametrization == "modal":
        # Its projection is of the simulation from rest only: said, not guessed.
        with pytest.raises(ValueError, match="`initial` must be 'rest'"):
            identify(data, arx, method=method, parametrization="modal",
                     initial="measured", rng=0, max_nfev=2000)  # fmt: skip
        return
    fit = identify(data, arx, method=method, parametrization=parametrization,
                   initial="measured", safe_start=True, rng=0,
                   max_nfev=2000)  # fmt: skip
    assert fit.cost <= floor
