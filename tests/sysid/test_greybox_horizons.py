"""The grey-box fit over growing horizons against an analytic case: a
lightly damped oscillator struck once, whose free-run cost over a long
record has a local minimum at every frequency that slips a whole number of
cycles behind the record, and over its first cycles has one."""

import numpy as np
import pytest
from scipy import signal

import spiralid as sid
from spiralid.sysid import GreyBox, Parameter
from spiralid.sysid.estimation.greybox import fit
from spiralid.sysid.estimation.greybox.fit import _horizon_lengths, _search_budget

TS = 0.05
K, C = 4.0, 0.02  # stiffness (N/m) and damping (N s/m) of a 1 kg mass


def oscillator(p):
    k, c = p
    return [[0.0, 1.0], [-k, -c]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]]


def struck(n=2000):
    u = np.zeros(n)
    u[0] = 1.0 / TS  # a unit impulse, held one sample
    a, b, c, d = (np.asarray(m, dtype=float) for m in oscillator((K, C)))
    _, y, _ = signal.dlsim(signal.cont2discrete((a, b, c, d), TS, "zoh"), u)
    return sid.IOData(u, y.ravel(), ts=TS)


def box(k0):
    return GreyBox(
        [
            Parameter("k", k0, (0.5, 20.0), "N/m"),
            Parameter("c", C, (0.001, 1.0), "N s/m", free=False),
        ],
        ss=oscillator,
    )


def test_the_horizons_are_shares_of_the_record_long_enough_to_fit():
    # 2 % of 100 samples is 2, not more than twice the 2 free parameters.
    assert _horizon_lengths((0.02, 0.1, 0.5), 100, 2) == [10, 50, 100]
    assert _horizon_lengths((), 100, 2) == [100]


@pytest.mark.parametrize(
    "value, error", [((0.5, 0.2), ValueError), ((0.0,), ValueError), ("x", TypeError)]
)
def test_bad_horizons_are_refused_in_one_line(value, error):
    with pytest.raises(error) as refused:
        sid.identify(struck(200), box(2.0), method="oe", horizons=value)
    message = str(refused.value)
    assert "\n" not in message and "`horizons`" in message, message


def test_growing_horizons_find_the_frequency_the_whole_record_hides():
    rec = struck()
    start = 2.0  # half the stiffness: 29 % below the frequency
    alone = sid.identify(rec, box(start), method="oe", horizons=())
    grown = sid.identify(
        rec, box(start), method="oe", horizons=(0.02, 0.05, 0.1, 0.25, 0.5)
    )
    assert abs(alone.values[0] - K) > 0.1  # the whole record's local minimum
    np.testing.assert_allclose(grown.values[0], K, rtol=1e-6)
    # The whole record's fit is one of the two candidates: never worse.
    assert grown.cost <= alone.cost
    assert grown.nfev > alone.nfev


@pytest.mark.parametrize(
    "share, times", [(1.0, 1), (0.5, 1), (0.25, 1), (0.1, 3), (0.05, 6)]
)
def test_a_short_horizon_search_gets_whole_budgets_for_its_samples(share, times):
    # 30 % of the whole record's search in samples, rounded to whole budgets:
    # a tenth of the record gets three, a quarter one.
    assert _search_budget({"max_nfev": 500}, 20, share) == 500 * times


def test_the_horizons_search_runs_with_its_budget(monkeypatch):
    budgets = []
    real = fit.minimize

    def counted(*args, **kwargs):
        budgets.append(kwargs["max_nfev"])
        return real(*args, **kwargs)

    monkeypatch.setattr(fit, "minimize", counted)
    sid.identify(struck(400), box(2.0), max_nfev=40, polish_nfev=2, horizons=(0.1,))
    assert budgets == [40, 120]  # the whole record's, then its first tenth's


def test_spiral_explores_what_a_shorter_horizon_cannot_determine(monkeypatch):
    # A third parameter the model ignores: flat on every horizon, so one
    # undetermined direction, stepped out four ways, four more polishes on
    # the first tenth; none on the whole record. Where the stiffness alone
    # is free, every direction is determined and nothing is explored.
    polished = []
    real = fit._polish

    def counted(stage, *args):
        polished.append(stage.y.size)
        return real(stage, *args)

    def ignoring(p):
        return oscillator(p[:2])

    ignored = GreyBox(
        [*box(2.0).parameters, Parameter("ignored", 1.0, (0.0, 2.0))], ss=ignoring
    )
    monkeypatch.setattr(fit, "_polish", counted)
    given = dict(max_nfev=40, polish_nfev=2, horizons=(0.1,), rng=0)
    sid.identify(struck(400), ignored, **given)
    assert polished == [400, 40, 40, 40, 40, 40, 400]
    polished.clear()
    sid.identify(struck(400), ignored, explore=False, **given)
    assert polished == [400, 40, 400]
    polished.clear()
    sid.identify(struck(400), box(2.0), **given)
    assert polished == [400, 40, 400]


@pytest.mark.parametrize("value", ["yes", 1, None])
def test_a_bad_explore_is_refused_in_one_line(value):
    with pytest.raises(TypeError) as refused:
        sid.identify(struck(200), box(2.0), max_nfev=40, explore=value)
    message = str(refused.value)
    assert "\n" not in message and "`explore`" in message, message
