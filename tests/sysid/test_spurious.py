"""Issue 47: the recommended method acts on its own modes table's diagnosis.

A pole the table flags (an interval that reaches |z| = 1, a cancelling
zero) is removed with its nearest zero and the rest refitted when the
likelihood-ratio test at 5 % allows, with the error's effective samples;
otherwise it is kept and the model says why. Checked against analytic
cases: the chi-square quantile of two degrees of freedom, an AR(1)
error's integrated autocorrelation time, and a plant whose spare pole is
known.
"""

import json

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.sysid import ARX, IdentifiedModel, IOData, identify, validate
from spiralid.sysid.estimation.core.cost import PaperCost
from spiralid.sysid.estimation.linear.outputerror import local_polish
from spiralid.sysid.estimation.spiral import spurious
from spiralid.sysid.estimation.spiral.spurious import (
    LEVEL,
    effective_samples,
    flagged_poles,
    remove_flagged,
    tolerance,
)

# The plant: one lightly damped pair, B = 0.5 q^-1 + 0.3 q^-2.
A_TRUE = np.array([-1.5, 0.7])
B_TRUE = np.array([0.0, 0.5, 0.3])


def _record(seed: int = 0, n: int = 1500) -> IOData:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = lfilter(B_TRUE, np.r_[1.0, A_TRUE], u)
    return IOData(u, y + 0.05 * np.std(y) * rng.standard_normal(n), ts=0.01)


def _with_spare_pole(pole: float, zero: float) -> np.ndarray:
    """The plant times (z - zero) / (z - pole): ARX(3, 3, 1) whose extra
    real pole a zero nearly cancels."""
    a = np.polymul(np.r_[1.0, A_TRUE], [1.0, -pole])[1:]
    b = np.polymul(B_TRUE[1:], [1.0, -zero])
    return np.r_[a, b]


def _tools(data: IOData, arx: ARX):
    cost = PaperCost(arx, data, predictor="simulation")

    def polish(start, reduced):
        return local_polish(start, reduced, data, "simulation", "rest")[0]

    def error(theta):
        return data.y - arx.simulate(theta, data.u)

    return cost, polish, error


def test_the_tolerance_is_the_chi_square_test_of_the_fixed_parameters():
    # chi2_0.95(2) = -2 ln 0.05: V_r / V <= 0.05^(-2 / N_eff).
    for n_eff in (20.0, 500.0, 4000.0):
        assert tolerance(2, n_eff) == pytest.approx(0.05 ** (-2 / n_eff) - 1, rel=1e-9)
    assert LEVEL == 0.05
    # Fewer effective samples, a wider tolerance; more parameters, too.
    assert tolerance(2, 50.0) > tolerance(2, 500.0)
    assert tolerance(4, 500.0) > tolerance(2, 500.0)


def test_effective_samples_follow_the_integrated_autocorrelation_time():
    rng = np.random.default_rng(1)
    white = rng.standard_normal(20_000)
    assert effective_samples(white) == pytest.approx(20_000, rel=0.1)
    # AR(1) with phi: tau = (1 + phi) / (1 - phi).
    for phi in (0.5, 0.9):
        ar = lfilter([1.0], [1.0, -phi], white)
        tau = (1 + phi) / (1 - phi)
        assert effective_samples(ar) == pytest.approx(20_000 / tau, rel=0.25)


def test_a_flagged_spare_pole_is_removed_and_the_plant_refitted():
    data = _record()
    arx = ARX(3, 3, 1)
    theta = _with_spare_pole(0.9995, 0.9990)
    flags = flagged_poles(theta, arx, data, "rest")
    assert [round(f.pole.real, 4) for f in flags] == [0.9995]
    cost, polish, error = _tools(data, arx)
    out, reduced, diagnosis = remove_flagged(
        theta, arx, data, "rest", cost, polish, error
    )
    assert reduced == ARX(2, 2, 1) and len(diagnosis.removed) == 1
    assert diagnosis.kept == []
    # The refit is the plant (the noise is 5 % of the output).
    np.testing.assert_allclose(out[:2], A_TRUE, atol=0.01)
    np.testing.assert_allclose(out[3:5], B_TRUE[1:], atol=0.02)
    assert out[2] == 0.0 and out[5] == 0.0
    assert diagnosis.removed[0]["cost_increase"] <= diagnosis.removed[0]["tolerance"]


def test_a_flagged_pole_that_costs_too_much_is_kept_and_the_model_says_why(
    monkeypatch,
):
    # Two modes, and a numerator with a complex zero pair; the first mode
    # flagged by hand (as a too wide interval would flag it): removing a
    # mode the output carries costs far beyond the test's tolerance.
    p1, p2 = 0.95 * np.exp(0.3j), 0.9 * np.exp(1.0j)
    a = np.poly([p1, np.conj(p1), p2, np.conj(p2)]).real
    b = 0.2 * np.poly([0.5 * np.exp(0.6j), 0.5 * np.exp(-0.6j)]).real
    rng = np.random.default_rng(2)
    u = rng.standard_normal(1500)
    y = lfilter(np.r_[0.0, b], a, u)
    data = IOData(u, y + 0.05 * np.std(y) * rng.standard_normal(u.size), ts=0.01)
    arx = ARX(4, 3, 1)
    theta = np.r_[a[1:], b]
    monkeypatch.setattr(
        spurious,
        "flagged_poles",
        lambda *args: [spurious.Flagged(complex(p1), ("interval reaches |z| = 1",))],
    )
    cost, polish, error = _tools(data, arx)
    out, reduced, diagnosis = remove_flagged(
        theta, arx, data, "rest", cost, polish, error
    )
    assert reduced == arx and np.array_equal(out, theta)
    assert diagnosis.removed == [] and len(diagnosis.kept) == 1
    kept = diagnosis.kept[0]
    assert kept["cost_increase"] > kept["tolerance"] > 0.0
    assert "was kept: removing it raised the estimation cost" in diagnosis.sentence()


def test_the_default_reports_its_effective_order_and_the_note_survives_a_file():
    # benchmarks/drift_process.py's record, seed 2 at ARX(8, 8, 0): the
    # default's minimum has poles whose intervals reach |z| = 1.
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parents[2] / "benchmarks" / "drift_process.py"
    spec = importlib.util.spec_from_file_location("drift_process", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    est, val = module.record(2).split(2 / 3)
    fit = identify(est, ARX(8, 8, 0), rng=2)
    assert fit.diagnosis is not None
    removed = [c for c in fit.cancellations if "reason" in c]
    assert len(removed) == len(fit.diagnosis["removed"]) >= 1
    k = sum(c["order"] for c in fit.cancellations)
    assert fit.effective_order == (8 - k, 8 - k)
    back = IdentifiedModel.from_dict(json.loads(json.dumps(fit.to_dict())))
    assert back.effective_order == fit.effective_order
    assert back.diagnosis == fit.diagnosis and back.reduction == fit.reduction
    summary = validate(fit, val, warmup=est).summary()
    assert "flagged pole" in summary
    # Without the cancellation nothing acts on the table.
    off = identify(est, ARX(8, 8, 0), rng=2, cancel=False)
    assert off.diagnosis is None and off.effective_order == (8, 8)


def test_an_explicit_margin_holds_every_refitted_pole_and_is_never_lifted():
    # The removals are refitted with the same margin: a time constant the
    # user gave bounds every pole of the returned model, as before.
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parents[2] / "benchmarks" / "drift_process.py"
    spec = importlib.util.spec_from_file_location("drift_process", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    est, _ = module.record(2).split(2 / 3)
    seconds = est.n * est.ts / 2
    fit = identify(est, ARX(8, 8, 0), rng=2, max_time_constant=seconds)
    assert fit.margin is None
    assert fit.max_pole_radius <= np.exp(-est.ts / seconds) + 1e-12


def test_a_flagged_complex_pair_is_removed_with_its_zero_pair():
    # The plant times a lightly damped pair at 20 Hz that a zero pair just
    # beside it cancels: the pair carries nothing the record can see.
    data = _record(3)
    p = 0.9995 * np.exp(2j * np.pi * 20.0 * data.ts)
    z = 0.9990 * np.exp(2j * np.pi * 20.05 * data.ts)
    a = np.polymul(np.r_[1.0, A_TRUE], np.poly([p, np.conj(p)]).real)[1:]
    b = np.polymul(B_TRUE[1:], np.poly([z, np.conj(z)]).real)
    arx = ARX(4, 4, 1)
    theta = np.r_[a, b]
    flags = flagged_poles(theta, arx, data, "rest")
    assert any(f.size == 2 and abs(f.pole - p) < 1e-9 for f in flags)
    cost, polish, error = _tools(data, arx)
    out, reduced, diagnosis = remove_flagged(
        theta, arx, data, "rest", cost, polish, error
    )
    assert reduced == ARX(2, 2, 1)
    assert [r["order"] for r in diagnosis.removed] == [2]
    np.testing.assert_allclose(out[:2], A_TRUE, atol=0.01)
    np.testing.assert_allclose(out[4:6], B_TRUE[1:], atol=0.02)
    assert out[[2, 3, 6, 7]].tolist() == [0.0, 0.0, 0.0, 0.0]
