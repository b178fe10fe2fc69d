"""Radius/angle rules against the literal formulas of eq. (4), (7), (8)."""

import warnings

import numpy as np
import pytest
from scipy import stats

from spiralid.optim import (
    ConstantSpiral,
    ExponentialSpiral,
    LinearSpiral,
    exponential_rule,
)


def _fp_raise():
    # Underflow to zero is harmless and silent by default; the rest must not occur.
    return np.errstate(over="raise", divide="raise", invalid="raise")


def literal_eq4(d, lower, upper, c1, c2):
    """Eq. (4) exactly as printed; fine where exp(c2 d) does not overflow."""
    return (lower - upper) / (1.0 + c1 / np.exp(c2 * d)) + upper


@pytest.mark.parametrize(
    ("lower", "upper", "c1", "c2"), [(0.1, 1.0, 100.0, 1.5), (0.1, 2.0, 10.0, 1.0)]
)
def test_matches_printed_formula(lower, upper, c1, c2):
    d = np.concatenate([np.logspace(-12, 2, 200), [0.0]])
    np.testing.assert_allclose(
        exponential_rule(d, lower, upper, c1, c2),
        literal_eq4(d, lower, upper, c1, c2),
        rtol=1e-13,
        atol=1e-15,
    )


def test_paper_constants_spot_values():
    # Hand-worked: d = ln(100)/1.5 makes c1/exp(c2 d) = 1, so r = (0.1 + 1)/2.
    rule = ExponentialSpiral()
    assert rule.radius(np.log(100.0) / 1.5) == pytest.approx(0.55, rel=1e-15)
    # d = ln(10) makes the angle's c1/exp(d) = 1: theta = (0.1 + 2)/2.
    assert rule.angle(np.log(10.0)) == pytest.approx(1.05, rel=1e-15)


def test_limits():
    rule = ExponentialSpiral()
    assert rule.radius(1e-300) == pytest.approx((0.1 - 1.0) / 101.0 + 1.0, rel=1e-15)
    assert rule.angle(1e-300) == pytest.approx((0.1 - 2.0) / 11.0 + 2.0, rel=1e-15)
    assert rule.radius(1e3) == 0.1
    assert rule.angle(1e3) == 0.1
    assert rule.radius(np.inf) == 0.1
    assert rule.angle(np.inf) == 0.1


def test_monotone_in_d():
    rule = ExponentialSpiral()
    d = np.concatenate([np.logspace(-300, 300, 2000), [np.inf]])
    for values in (rule.radius(d), rule.angle(d)):
        assert np.all(np.diff(values) <= 0.0)
    moderate = np.linspace(0.01, 10.0, 500)
    assert np.all(np.diff(rule.radius(moderate)) < 0.0)
    assert np.all(np.diff(rule.angle(moderate)) < 0.0)


@pytest.mark.parametrize(
    "constants",
    [
        dict(),
        dict(r_c1=1e-300, r_c2=1e300, th_c1=1e300, th_c2=1e-300),
        dict(r_c1=1.7e308, r_c2=5e-324, th_c1=5e-324, th_c2=1.7e308),
    ],
)
def test_finite_and_warning_free_for_huge_d(constants):
    rule = ExponentialSpiral(**constants)
    d = np.array([0.0, 1e-320, 1.0, 1e100, 1e300, 1.7e308, np.inf])
    with warnings.catch_warnings(), _fp_raise():
        warnings.simplefilter("error")
        r, theta = rule(d, np.random.default_rng(0))
    assert np.all(np.isfinite(r)) and np.all(np.isfinite(theta))
    assert np.all((r >= rule.r_l) & (r <= rule.r_u))
    assert np.all((theta >= rule.th_l) & (theta <= rule.th_u))


def test_zero_deviation_draws_uniform_in_order():
    rule = ExponentialSpiral()
    d = np.array([0.0, 2.0, 0.0, 0.0, 0.5])
    r, theta = rule(d, np.random.default_rng(7))
    # Independent replay of the documented draw order: radii, then angles.
    ref = np.random.default_rng(7)
    r_ref = ref.uniform(0.1, 1.0, 3)
    th_ref = ref.uniform(0.1, 2.0, 3)
    np.testing.assert_array_equal(r[[0, 2, 3]], r_ref)
    np.testing.assert_array_equal(theta[[0, 2, 3]], th_ref)
    np.testing.assert_allclose(r[[1, 4]], literal_eq4(d[[1, 4]], 0.1, 1.0, 100, 1.5))


def test_zero_deviation_distribution_is_uniform():
    r, theta = ExponentialSpiral()(np.zeros(4000), np.random.default_rng(3))
    assert stats.kstest(r, stats.uniform(0.1, 0.9).cdf).pvalue > 1e-3
    assert stats.kstest(theta, stats.uniform(0.1, 1.9).cdf).pvalue > 1e-3


def test_positive_deviations_draw_nothing():
    rng = np.random.default_rng(5)
    before = rng.bit_generator.state
    ExponentialSpiral()(np.array([0.1, np.inf, 3.0]), rng)
    assert rng.bit_generator.state == before


def test_constant_rule():
    r, theta = ConstantSpiral()(np.array([0.0, 1.0]), np.random.default_rng(0))
    assert (r, theta) == (0.95, np.pi / 4)
    assert ConstantSpiral(radius=1, angle=-0.3)(None, None) == (1.0, -0.3)


@pytest.mark.parametrize("radius", [0.0, -0.5, 1.0000001, np.nan, np.inf])
def test_constant_radius_out_of_range(radius):
    with pytest.raises(
        ValueError, match=r"^`radius` must be|^`radius` must be a finite"
    ):
        ConstantSpiral(radius=radius)


def test_constant_radius_message():
    with pytest.raises(ValueError, match=r"^`radius` must be in \(0, 1\]; got 1\.5"):
        ConstantSpiral(radius=1.5)
    with pytest.raises(ValueError, match=r"^`angle` must be a finite number"):
        ConstantSpiral(angle=np.inf)


def test_linear_rule_values():
    rule = LinearSpiral()
    r, theta = rule(np.array([0.0, 1.0, 4.0, np.inf]), None)
    # d_max = 4 (largest finite): fractions 0, 1/4, 1, 1 (inf -> lower).
    np.testing.assert_allclose(r, [1.0, 1.0 - 0.9 / 4, 0.1, 0.1], rtol=1e-15)
    np.testing.assert_allclose(theta, [2.0, 2.0 - 1.9 / 4, 0.1, 0.1], rtol=1e-15)
    fixed = LinearSpiral(d_max=2.0)
    r, _ = fixed(np.array([0.0, 1.0, 2.0, 50.0]), None)
    np.testing.assert_allclose(r, [1.0, 0.55, 0.1, 0.1], rtol=1e-15)
    r, theta = rule(np.zeros(3), None)
    np.testing.assert_array_equal(r, 1.0)
    r, theta = rule(np.array([np.inf, np.inf]), None)
    np.testing.assert_array_equal(theta, 0.1)
    with warnings.catch_warnings(), _fp_raise():
        warnings.simplefilter("error")
        r, _ = LinearSpiral(d_max=1e-300)(np.array([1e300, 0.0]), None)
    np.testing.assert_array_equal(r, [0.1, 1.0])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(r_l=0.5, r_u=0.5), r"^`r_l` and `r_u` must satisfy 0 < r_l < r_u <= 1"),
        (dict(r_l=0.0), r"^`r_l` and `r_u` must satisfy .*got r_l=0\.0"),
        (dict(r_u=1.2), r"^`r_l` and `r_u` must satisfy .*r_u=1\.2"),
        (dict(th_l=2.0, th_u=1.0), r"^`th_l` and `th_u` must satisfy th_l < th_u"),
        (dict(th_u=np.inf), r"^`th_u` must be a finite number"),
        (dict(r_c1=0.0), r"^`r_c1` must be a finite number > 0; got 0\.0"),
        (dict(th_c2=-1.0), r"^`th_c2` must be a finite number > 0"),
        (dict(r_c2=np.nan), r"^`r_c2` must be a finite number"),
    ],
)
def test_exponential_bad_constants(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ExponentialSpiral(**kwargs)


def test_linear_bad_constants():
    with pytest.raises(ValueError, match=r"^`d_max` must be a finite number > 0"):
        LinearSpiral(d_max=0.0)
    with pytest.raises(ValueError, match=r"^`r_l` and `r_u` must satisfy"):
        LinearSpiral(r_l=1.0, r_u=0.2)


def test_exponential_rule_rejects_nan_or_negative_d():
    with pytest.raises(ValueError, match=r"^`d` must be >= 0 \(inf allowed\)"):
        exponential_rule(np.array([1.0, np.nan]), 0.1, 1.0, 100.0, 1.5)
    with pytest.raises(ValueError, match=r"^`d` must be >= 0"):
        exponential_rule(-1.0, 0.1, 1.0, 100.0, 1.5)


def test_exponential_rule_keeps_shape():
    d = np.array([[0.0, 1.0], [2.0, np.inf]])
    out = exponential_rule(d, 0.1, 1.0, 100.0, 1.5)
    assert out.shape == (2, 2)
    np.testing.assert_allclose(
        out[:, :1].ravel(), literal_eq4(d[:, 0], 0.1, 1, 100, 1.5)
    )
    assert np.ndim(exponential_rule(0.5, 0.1, 1.0, 100.0, 1.5)) == 0


@pytest.mark.parametrize(
    ("args", "match"),
    [
        # ln(0) and ln(nan) used to give a math-domain error or NaN values.
        ((0.1, 1.0, 0.0, 1.5), r"^`c1` must be a finite number > 0; got 0\.0"),
        ((0.1, 1.0, np.nan, 1.5), r"^`c1` must be a finite number > 0; got nan"),
        # A negative c2 would make the rule rise with d, silently.
        ((0.1, 1.0, 100.0, -1.0), r"^`c2` must be a finite number > 0; got -1\.0"),
        ((None, 1.0, 100.0, 1.5), r"^`lower` must be a finite number; got None"),
        ((1.0, 0.1, 100.0, 1.5), r"^`lower` and `upper` must satisfy lower < upper"),
    ],
)
def test_exponential_rule_bad_constants(args, match):
    with pytest.raises((TypeError, ValueError), match=match):
        exponential_rule(np.array([1.0]), *args)


def test_exponential_rule_bad_d_types():
    with pytest.raises(TypeError, match=r"^`d` must be an array of real numbers"):
        exponential_rule("a", 0.1, 1.0, 100.0, 1.5)
    with pytest.raises(ValueError, match=r"^`d` must be an array of real numbers"):
        exponential_rule([[1.0], [2.0, 3.0]], 0.1, 1.0, 100.0, 1.5)


@pytest.mark.parametrize("rule", [ExponentialSpiral(), LinearSpiral()])
@pytest.mark.parametrize(
    "d", [np.array([0.5, np.nan]), np.array([-1.0]), np.zeros((2, 2)), 0.5]
)
def test_rules_reject_bad_deviations(rule, d):
    with pytest.raises(ValueError, match=r"^`d` must be a 1-D array of deviations"):
        rule(d, np.random.default_rng(0))
