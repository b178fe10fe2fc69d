"""Spiral search over modal coordinates with the numerator projected out."""

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.optim import Restarts
from spiralid.sysid import ARX, IOData
from spiralid.sysid.estimation.linear.modal import ModalParametrization
from spiralid.sysid.estimation.linear.varpro import ProjectedCost
from spiralid.sysid.estimation.spiral.projected import (
    PatientRestarts,
    frequency_seeds,
    projected_spiral,
)

# A pure spiral search over the modes; tests set what they exercise.
PLAIN = dict(n_points=50, polish_every=None, polish_nfev=10, restarts=None)


def _two_modes(n=3000, ts=0.002, noise=0.0, seed=0):
    """Two lightly damped modes at 12 and 40 Hz, sampled exactly."""
    par = ModalParametrization(4, ts)
    a = par.to_denominator([12.0, 40.0, np.log10(0.02), np.log10(0.03)])
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = lfilter([0.0, 0.5, 0.2, -0.1], np.r_[1.0, a], u)
    return IOData(u, y + noise * rng.standard_normal(n), ts=ts), a


def test_memetic_search_recovers_a_two_mode_system():
    data, a_true = _two_modes()
    cost = ProjectedCost(ARX(4, 3, 1), data)
    par = ModalParametrization(4, data.ts)
    kw = PLAIN | dict(max_nfev=3000, polish_every=5, rng=0)
    res = projected_spiral(cost, par, "ebsda", **kw)
    assert res.fun < 1e-3  # percent RMS error: the true model costs 0
    assert res.x[:4] == pytest.approx(a_true, abs=1e-6)
    assert res.x[4:] == pytest.approx([0.5, 0.2, -0.1], abs=1e-6)
    assert res.nfev <= 3000


def test_same_seed_same_result_and_budget_respected():
    data, _ = _two_modes(noise=0.05)
    cost = ProjectedCost(ARX(4, 3, 1), data)
    par = ModalParametrization(4, data.ts)
    kw = PLAIN | dict(
        max_nfev=1500, polish_every=5, restarts=Restarts(growth=1, stall=10), rng=7
    )
    one = projected_spiral(cost, par, "sda", **kw)
    two = projected_spiral(cost, par, "sda", **kw)
    assert np.array_equal(one.x, two.x) and one.fun == two.fun
    assert one.nfev <= 1500
    assert np.all(np.diff(one.history) <= 0)
    assert one.history.size == one.nit + one.n_restarts + 1
    assert one.status == 1  # the budget ended it


def test_an_initial_point_bounds_the_result():
    data, _ = _two_modes(noise=0.05)
    cost = ProjectedCost(ARX(4, 3, 1), data)
    par = ModalParametrization(4, data.ts)
    start = np.array([[12.0, 40.0, np.log10(0.02), np.log10(0.03)]])
    res = projected_spiral(cost, par, "sda", max_nfev=500, x0=start, rng=0, **PLAIN)
    assert res.fun <= cost(par.to_denominator(start))[0]


def test_frequency_seeds_sit_at_the_modes():
    data, _ = _two_modes(n=8000)
    par = ModalParametrization(4, data.ts)
    seeds = frequency_seeds(data, par, 10, rng=0)
    assert seeds.shape == (10, 4)
    assert np.all((seeds >= par.bounds[:, 0]) & (seeds <= par.bounds[:, 1]))
    # Within about a resolution cell (fs / nperseg) of the true modes.
    assert np.abs(np.sort(seeds[:, :2], axis=1) - [12.0, 40.0]).max() < 2.0


def test_patience_stops_once_a_restart_finds_no_lower_basin():
    data, _ = _two_modes(noise=0.05)
    cost = ProjectedCost(ARX(4, 3, 1), data)
    par = ModalParametrization(4, data.ts)
    kw = PLAIN | dict(max_nfev=20_000, polish_every=5, rng=3)
    full = projected_spiral(
        cost, par, "ebsda", **kw | dict(restarts=Restarts(growth=1, stall=10))
    )
    patient = PatientRestarts(growth=1, stall=10, patience=1)
    early = projected_spiral(cost, par, "ebsda", **kw | dict(restarts=patient))
    assert full.status == 1 and not full.converged
    assert early.converged and early.status == 0 and "Converged" in early.message
    assert early.nfev < full.nfev
    # The last population ended no lower than the best before it (by rtol),
    # and every earlier one lowered it: the first is always a new basin.
    ends = np.array([c for _, c in early.populations])
    assert ends[-1] >= ends[:-1].min() * (1 - 1e-6)
    assert np.all(np.diff(np.minimum.accumulate(ends[:-1])) < 0)
    # A stop at convergence still polishes the best at the end.
    assert early.fun <= ends.min()


def test_patience_is_checked():
    for bad, match in ((dict(patience=0), "`patience`"), (dict(rtol=0), "`rtol`")):
        with pytest.raises(ValueError, match=match):
            PatientRestarts(**bad)


def test_the_learned_metric_rule_restarts_and_stops_inside_the_spiral_method():
    # Its search keeps its centre's cost as a float, not a population's
    # array: the spiral method's restart and stop read it through
    # `centre_cost` (the gallery's "no gradient" route).
    import spiralid as sid

    est = sid.datasets.robot_arm().split(2 / 3)[0]
    fit = sid.identify(
        est, sid.ARX(4, 4, 0), rng=0, rule="learned-metric", polish_every=None,
        max_nfev=3000,
    )  # fmt: skip
    assert np.isfinite(fit.cost) and fit.result["nfev"] <= 3000
