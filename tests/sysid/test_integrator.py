"""Integrating outputs: a known pole at z = 1 factored out of the estimation
(`identify(integrator=True)`, `spiralid identify --integrator`)."""

import json

import numpy as np
import pytest
from clitools import run
from scipy import signal

from spiralid.sysid import ARX, IdentifiedModel, IOData, identify, validate
from spiralid.sysid.models.polynomials import deflate_integrator, with_integrator

A_STABLE = [-1.6, 0.89]  # a lightly damped mode
B = [0.0, 0.02, 0.015]


def _integrating_record(seed: int, count: int = 1) -> IOData:
    """A random ARX model times 1 / (1 - z^-1)^count, excited from rest."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(900)
    a = np.r_[1.0, with_integrator(A_STABLE, count)]
    y = signal.lfilter(B, a, u) + 0.01 * rng.standard_normal(900)
    return IOData(u, y, ts=0.01)


def test_deflating_and_adding_an_integrator_round_trip():
    a = with_integrator(A_STABLE)
    assert np.polyval(np.r_[1.0, a], 1.0) == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(deflate_integrator(a), A_STABLE, rtol=1e-12)
    # Twice: (1 - z^-1)^2 = 1 - 2 z^-1 + z^-2, by hand.
    np.testing.assert_allclose(with_integrator([], 2), [-2.0, 1.0])
    a2 = with_integrator(A_STABLE, 2)
    np.testing.assert_allclose(a2, np.convolve([1.0, *A_STABLE], [1.0, -2.0, 1.0])[1:])
    np.testing.assert_allclose(deflate_integrator(a2, 2), A_STABLE, rtol=1e-12)


@pytest.mark.parametrize("method", ["oe", "spiral"])
def test_an_integrating_record_is_identified_to_its_true_integrator(method):
    est, val = _integrating_record(0).split(2 / 3)
    fit = identify(est, ARX(3, 3, 0), method=method, rng=0, integrator=True)
    a = fit.theta[:3]
    assert np.polyval(np.r_[1.0, a], 1.0) == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(fit.free_denominator, A_STABLE, atol=0.02)
    assert fit.integrator and fit.is_stable  # marginally stable by design
    report = validate(fit, val, warmup=est)
    assert report.fit_percent > 95
    assert report.stable and "known integrator" in report.summary()
    # Without it the same structure cannot hold the ramp as well.
    plain = validate(identify(est, ARX(3, 3, 0), method=method, rng=0), val,
                     warmup=est)  # fmt: skip
    assert plain.fit_percent < report.fit_percent


def test_a_double_integrator_is_identified_as_two_known_poles_at_one():
    # torque -> angle of a rigid body: two poles at z = 1, which a margin on
    # the estimated poles must not touch.
    est, val = _integrating_record(3, count=2).split(2 / 3)
    fit = identify(est, ARX(4, 3, 0), method="spiral", rng=0, integrator=2)
    assert fit.integrator == 2 and fit.is_stable
    np.testing.assert_allclose(fit.theta[:4], with_integrator(fit.free_denominator, 2))
    np.testing.assert_allclose(fit.free_denominator, A_STABLE, atol=0.02)
    np.testing.assert_allclose(fit.theta[4:], B, atol=0.01)
    assert validate(fit, val, warmup=est).fit_percent > 95
    again = IdentifiedModel.from_dict(fit.to_dict())
    assert again.integrator == 2
    np.testing.assert_array_equal(again.free_denominator, fit.free_denominator)


def test_integrator_refuses_what_it_cannot_do():
    est = _integrating_record(1)
    with pytest.raises(ValueError, match="needs a denominator"):
        identify(est, ARX(0, 3, 0), method="oe", integrator=True)
    with pytest.raises(ValueError, match="initial='rest'"):
        identify(est, ARX(3, 3, 0), method="oe", integrator=True,
                 initial="measured")  # fmt: skip
    with pytest.raises(ValueError, match="`integrator` must be True, False or a count"):
        identify(est, ARX(3, 3, 0), method="oe", integrator="yes")
    with pytest.raises(ValueError, match="`integrator` must be True, False or a count"):
        identify(est, ARX(3, 3, 0), method="oe", integrator=-1)
    with pytest.raises(ValueError, match=r"`integrator` = 4 needs .* na >= 4"):
        identify(est, ARX(3, 3, 0), method="oe", integrator=4)
    with pytest.raises(ValueError, match="poles at z = 1"):
        IdentifiedModel([-1.6, 0.89, 0.0, 0.02, 0.015], arx=ARX(2, 3, 0),
                        ts=0.01, method="oe", integrator=True)  # fmt: skip


def test_the_command_line_carries_the_integrator_through_model_json(tmp_path):
    data = _integrating_record(2)
    np.savez(tmp_path / "rec.npz", u=data.u, y=data.y, ts=0.01)
    made = run("identify", "rec.npz", "--na", "3", "--nb", "3", "--method", "oe",
               "--integrator", "--out", "m", cwd=tmp_path)  # fmt: skip
    assert made.returncode == 0, made.stderr
    model = json.loads((tmp_path / "m" / "model.json").read_text())
    assert model["integrator"] == 1
    again = run("validate", "m/model.json", "rec.npz", "--fraction", "2/3",
                cwd=tmp_path)  # fmt: skip
    assert again.returncode == 0, again.stderr
    assert "known integrator" in again.stdout
