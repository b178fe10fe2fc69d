"""identify(method="spiral"): the recommended spiral identification."""

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.sysid import ARX, IdentifiedModel, IOData, PaperCost, identify
from spiralid.sysid.estimation.core.estimators import DEFAULT_METHOD
from spiralid.sysid.estimation.linear.modal import ModalParametrization
from spiralid.sysid.estimation.linear.parametrizations import make_parametrization

ARX4 = ARX(4, 3, 1)


@pytest.fixture(scope="module")
def two_modes():
    """Two lightly damped modes (12 and 40 Hz) with output noise."""
    ts = 0.002
    a = ModalParametrization(4, ts).to_denominator(
        [12.0, 40.0, np.log10(0.02), np.log10(0.03)]
    )
    rng = np.random.default_rng(0)
    u = rng.standard_normal(3000)
    y = lfilter([0.0, 0.5, 0.2, -0.1], np.r_[1.0, a], u)
    return IOData(u, y + 0.2 * rng.standard_normal(u.size), ts=ts)


def test_spiral_is_the_default_and_reaches_output_error(two_modes):
    assert DEFAULT_METHOD == "spiral"
    oe = identify(two_modes, ARX4, method="oe")
    for seed in range(3):
        fit = identify(two_modes, ARX4, rng=seed, max_nfev=3000)
        assert (fit.method, fit.parametrization) == ("spiral", "modal")
        assert fit.cost <= 1.01 * oe.cost
        assert fit.result.nfev <= 3000
        # The budget ended the search, or it converged before (status 0).
        assert fit.result.status == (0 if fit.result.raw.converged else 1)
        # The reported cost is the paper's, computed independently here.
        assert fit.cost == pytest.approx(PaperCost(ARX4, two_modes)(fit.theta))


def test_same_seed_same_model(two_modes):
    one = identify(two_modes, ARX4, rng=4, max_nfev=1500)
    two = identify(two_modes, ARX4, rng=4, max_nfev=1500)
    assert np.array_equal(one.theta, two.theta)
    back = IdentifiedModel.from_dict(one.to_dict())
    assert back.parametrization == "modal" and np.array_equal(back.theta, one.theta)


def test_modal_parametrization_maps_to_the_projected_model(two_modes):
    par = make_parametrization("modal", two_modes, ARX4)
    assert par.n_search == 4 and par.default_bounds().shape == (4, 2)
    oe = identify(two_modes, ARX4, method="oe")
    x = par.from_theta(oe.theta)
    theta = par.to_theta(x)
    # Same denominator; the projected numerator is at least as good as OE's.
    assert theta[:4] == pytest.approx(oe.theta[:4], abs=1e-9)
    cost = PaperCost(ARX4, two_modes)
    assert cost(theta) <= cost(oe.theta) + 1e-9


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(initial="measured"), "`initial` must be 'rest'"),
        (dict(predictor="one-step"), "`predictor` must be 'simulation'"),
        (dict(parametrization="reflection"), "`parametrization` must be 'modal'"),
        (dict(target=1.0), "`target` does not apply to method 'spiral'"),
    ],
)
def test_unsupported_settings_are_refused_clearly(two_modes, kwargs, match):
    with pytest.raises(ValueError, match=match):
        identify(two_modes, ARX4, **kwargs)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(max_nfev=10), "`max_nfev` must be an integer >= 50"),
        (dict(polish_every=0), "`polish_every`"),
        (dict(restarts=2.5), "`restarts` must be True, False or a Restarts"),
        (dict(frequency_seeds=-1), "`frequency_seeds`"),
        (dict(n_points=1), "`n_points`"),
        (dict(stop="never"), "`stop` of method 'spiral' must be one of"),
    ],
)
def test_bad_search_options_are_named(two_modes, kwargs, match):
    with pytest.raises((TypeError, ValueError), match=match):
        identify(two_modes, ARX4, **kwargs)


def test_the_search_stops_when_a_restart_finds_no_lower_basin(two_modes):
    # stop="converged" ends the search once a fresh population falls back
    # into a basin already found; stop="budget" spends it all, as before.
    # Output error's cost holds either way.
    oe = identify(two_modes, ARX4, method="oe")
    default = identify(two_modes, ARX4, rng=1, max_nfev=8000, stop="converged")
    budget = identify(two_modes, ARX4, rng=1, max_nfev=8000, stop="budget")
    assert default.result.raw.converged and default.result.status == 0
    assert "Converged" in default.result.message
    assert not budget.result.raw.converged and budget.result.status == 1
    assert default.result.nfev < budget.result.nfev
    for fit in (default, budget):
        assert fit.result.get("fun_full", fit.cost) <= oe.cost * (1 + 1e-12)


def _output_error_work(data, arx):
    """Residual evaluations of output error's two polishes, counted here
    from the same starts (least squares and Steiglitz-McBride)."""
    from spiralid.sysid.estimation.linear.margin import max_radius
    from spiralid.sysid.estimation.linear.outputerror import (
        local_polish,
        steiglitz_mcbride,
    )
    from spiralid.sysid.models.arx import arx_least_squares

    ls = arx_least_squares(data, arx)
    radius = max_radius(data.ts, data.n * data.ts)
    return sum(
        local_polish(start, arx, data, "simulation", max_radius=radius)[1].nfev
        for start in (ls, steiglitz_mcbride(data, arx, ls))
    )


def test_the_default_stop_ties_the_search_to_output_errors_work(two_modes):
    # stop="work" (the default): output error first, then a search whose
    # budget is WORK.search evaluations per evaluation output error needed
    # (at least two populations), never above max_nfev; the cost stays at or
    # below output error's, whose minimum is among those kept.
    from spiralid.sysid.estimation.spiral.recommended import WORK

    oe = identify(two_modes, ARX4, method="oe")
    work = _output_error_work(two_modes, ARX4)
    fit = identify(two_modes, ARX4, rng=1)
    res = fit.result
    assert res.oe_work == work
    assert res.caps["search"] == max(100, round(WORK.search * work))
    assert res.raw.nfev <= res.caps["search"]
    assert res.caps["polish"] == max(WORK.least, round(WORK.polish * work))
    assert res.refine.runs["search"][1].nfev <= res.caps["polish"]
    assert fit.result.get("fun_full", fit.cost) <= oe.cost * (1 + 1e-12)
    # A smaller max_nfev still caps the search.
    small = identify(two_modes, ARX4, rng=1, max_nfev=60)
    assert small.result.caps["search"] == 60 and small.result.raw.nfev <= 60
    # The other stops leave the budget alone and measure nothing first.
    converged = identify(two_modes, ARX4, rng=1, stop="converged")
    assert converged.result.oe_work is None and converged.result.caps == {}
