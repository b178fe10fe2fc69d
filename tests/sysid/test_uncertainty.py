"""Parameter covariance and modes with intervals.

References: least squares' textbook covariance ``s^2 (Phi^T Phi)^-1`` built
here by hand, the spread of estimates over noise realisations (Monte Carlo),
a finite-difference delta method on NumPy's roots, and a plant whose mode is
known exactly.
"""

import json

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.sysid import ARX, IdentifiedModel, IOData, identify
from spiralid.sysid.estimation.core.uncertainty import parameter_covariance
from spiralid.sysid.models.modes import mode_table

TS = 0.01


def _plant(frequency=2.0, damping=0.05):
    wn = 2 * np.pi * frequency
    p = np.exp((-damping * wn + 1j * wn * np.sqrt(1 - damping**2)) * TS)
    return np.poly([p, np.conj(p)]).real


def _record(rng, n=500, noise=0.2):
    u = rng.standard_normal(n)
    y0 = lfilter([0.0, 0.01, 0.01], _plant(), u)
    return u, y0, noise * np.std(y0)


def test_least_squares_covariance_is_the_textbook_formula():
    rng = np.random.default_rng(3)
    u, y0, sigma = _record(rng)
    data = IOData(u, y0 + sigma * rng.standard_normal(u.size), ts=TS)
    fit = identify(data, ARX(2, 2, 1), method="ls")
    y = data.y
    phi = np.column_stack([-y[1:-1], -y[:-2], u[1:-1], u[:-2]])
    e = y[2:] - phi @ fit.theta
    s2 = e @ e / (e.size - 4)
    np.testing.assert_allclose(fit.noise_variance, s2, rtol=1e-10)
    np.testing.assert_allclose(
        fit.covariance, s2 * np.linalg.inv(phi.T @ phi), rtol=1e-8
    )


def test_output_error_intervals_are_calibrated_over_noise_realisations():
    # 100 records of one plant (2 Hz, damping 0.05) with white output noise,
    # fitted at the true order by output error: the standard errors match
    # the estimates' spread, and the 95 % intervals cover the true frequency
    # and damping about 95 % of the time (binomial sd 2.2 points at 100).
    rng = np.random.default_rng(0)
    u, y0, sigma = _record(rng)
    rows = []
    for _ in range(100):
        data = IOData(u, y0 + sigma * rng.standard_normal(u.size), ts=TS)
        modes = identify(data, ARX(2, 2, 1), method="oe").modes
        assert len(modes) == 1 and not modes.spurious[0]
        rows.append(
            (
                modes.frequency[0],
                modes.frequency_se[0],
                *modes.frequency_interval[0],
                modes.damping[0],
                modes.damping_se[0],
                *modes.damping_interval[0],
            )
        )
    f, f_se, f_lo, f_hi, d, d_se, d_lo, d_hi = np.array(rows).T
    assert np.std(f) == pytest.approx(np.mean(f_se), rel=0.3)
    assert np.std(d) == pytest.approx(np.mean(d_se), rel=0.3)
    assert 0.88 <= np.mean((f_lo <= 2.0) & (2.0 <= f_hi)) <= 1.0
    assert 0.88 <= np.mean((d_lo <= 0.05) & (0.05 <= d_hi)) <= 1.0


def test_delta_method_matches_finite_differences_of_the_roots():
    rng = np.random.default_rng(1)
    a = np.poly([0.9 * np.exp(0.3j), 0.9 * np.exp(-0.3j), 0.7 * np.exp(1.1j),
                 0.7 * np.exp(-1.1j), 0.5]).real[1:]  # fmt: skip
    root = rng.standard_normal((5, 5))
    cov = 1e-6 * root @ root.T
    table = mode_table(a, [0.0, 1.0, 0.3], TS, covariance=cov)

    def frequencies(coefficients):
        p = np.roots(np.r_[1.0, coefficients])
        p = p[p.imag > 0]
        return np.sort(np.abs(np.log(p)) / (2 * np.pi * TS))

    step = 1e-7
    grad = np.column_stack(
        [
            (frequencies(a + step * e) - frequencies(a - step * e)) / (2 * step)
            for e in np.eye(5)
        ]
    )
    expected = np.sqrt(np.einsum("ik,kl,il->i", grad, cov, grad))
    np.testing.assert_allclose(table.frequency_se, expected, rtol=1e-5)
    np.testing.assert_allclose(table.frequency, frequencies(a), rtol=1e-12)


def test_an_over_order_model_flags_its_extra_modes_and_keeps_the_true_one():
    rng = np.random.default_rng(2)
    u, y0, sigma = _record(rng, n=1500, noise=0.05)
    data = IOData(u, y0 + sigma * rng.standard_normal(u.size), ts=TS)
    modes = identify(data, ARX(6, 6, 0), method="oe").modes
    true = np.argmin(np.abs(modes.frequency - 2.0))
    assert abs(modes.frequency[true] - 2.0) < 0.01
    assert not modes.spurious[true]
    assert modes.share[true] > 0.9
    others = np.delete(np.arange(len(modes)), true)
    assert np.all(modes.spurious[others])


def test_covariance_and_modes_survive_model_json():
    rng = np.random.default_rng(4)
    u, y0, sigma = _record(rng)
    data = IOData(u, y0 + sigma * rng.standard_normal(u.size), ts=TS)
    fit = identify(data, ARX(2, 2, 1), method="oe")
    text = json.dumps(fit.to_dict())
    back = IdentifiedModel.from_dict(json.loads(text))
    np.testing.assert_array_equal(back.covariance, fit.covariance)
    assert back.noise_variance == fit.noise_variance
    assert json.loads(text)["modes"]["modes"][0]["frequency_hz"] == pytest.approx(
        2.0, abs=0.01
    )


def test_an_undetermined_direction_has_an_infinite_variance():
    # B = 0 leaves A undetermined: the Jacobian's A columns vanish.
    rng = np.random.default_rng(5)
    u = rng.standard_normal(300)
    data = IOData(u, 0.1 * rng.standard_normal(300), ts=TS)
    cov, _ = parameter_covariance(
        [-1.2, 0.5, 0.0, 0.0], ARX(2, 2, 1), data, "simulation"
    )
    assert np.all(np.isinf(np.diag(cov)[:2]))
    assert np.all(np.isfinite(np.diag(cov)[2:]))


def test_too_short_a_record_for_a_covariance_is_named():
    data = IOData(np.arange(4.0), np.arange(4.0) ** 2, ts=TS)
    with pytest.raises(ValueError, match="too short for a covariance"):
        parameter_covariance(np.zeros(6), ARX(3, 3, 0), data, "one-step")


def test_a_pole_at_the_origin_does_not_swamp_the_modes_shares():
    # Two modes and a real pole ever closer to z = 0: the modes keep their
    # shares and neither is called spurious.
    pairs = [np.exp((-0.02 + 1j) * w * TS) for w in (2 * np.pi * 5, 2 * np.pi * 12)]
    b = [0.0, 1.0, 0.3, -0.2, 0.1, 0.05]
    shares = []
    for c in (0.5, 1e-6, 1e-10):
        a = np.poly([*pairs, *np.conj(pairs), c]).real[1:]
        table = mode_table(a, b, TS, covariance=np.eye(5) * 1e-10)
        assert not np.any(table.spurious), (c, table.share)
        shares.append(table.share)
    np.testing.assert_allclose(shares[1], shares[2], rtol=1e-3)


def test_the_factor_keeps_a_delta_method_variance_that_the_matrix_rounds_away():
    # J with condition 1e9: C = s^2 (J^T J)^-1 spans 18 orders of magnitude,
    # and g^T C g along the best-determined direction v_1 is lost in C's
    # rounding, while |R g|^2 with R = s S^-1 V^T keeps it. Exact value:
    # s^2 / S_1^2 = s^2 (S_1 = 1, V orthonormal).
    from spiralid.sysid.models.modes import _Root, _spread

    rng = np.random.default_rng(6)
    v, _ = np.linalg.qr(rng.standard_normal((6, 6)))
    singular = np.logspace(0, -9, 6)
    root = 0.01 * v.T / singular[:, None]
    spread = _spread(v[:, :1].T, _Root(root))
    np.testing.assert_allclose(spread, [0.01], rtol=1e-9)


def test_factor_and_matrix_agree_where_the_matrix_is_well_conditioned():
    rng = np.random.default_rng(8)
    root = rng.standard_normal((5, 5)) * 1e-3
    a = np.poly([0.9 * np.exp(0.3j), 0.9 * np.exp(-0.3j), 0.7 * np.exp(1.1j),
                 0.7 * np.exp(-1.1j), 0.5]).real[1:]  # fmt: skip
    by_root = mode_table(a, [0.0, 1.0, 0.3], TS, factor=root)
    by_matrix = mode_table(a, [0.0, 1.0, 0.3], TS, covariance=root.T @ root)
    np.testing.assert_allclose(by_root.frequency_se, by_matrix.frequency_se, rtol=1e-9)
    np.testing.assert_allclose(by_root.damping_se, by_matrix.damping_se, rtol=1e-9)
