"""The modal parametrisation against poles computed by hand."""

import numpy as np
import pytest

from spiralid.sysid import is_stable_polynomial
from spiralid.sysid.estimation.linear.modal import ModalParametrization


def _roots(a):
    return np.sort_complex(np.roots(np.r_[1.0, a]))


def test_underdamped_section_has_the_sampled_continuous_poles():
    # 10 Hz, zeta = 0.05, ts = 0.01 by hand: s = -zeta wn +- j wn sqrt(1 - zeta^2),
    # z = exp(s ts) = rho exp(+-j phi).
    ts, f, zeta = 0.01, 10.0, 0.05
    wn = 2 * np.pi * f
    rho = np.exp(-zeta * wn * ts)
    phi = wn * np.sqrt(1 - zeta**2) * ts
    a = ModalParametrization(2, ts).to_denominator([f, np.log10(zeta)])
    assert a == pytest.approx([-2 * rho * np.cos(phi), rho**2], rel=1e-13)
    expected = np.sort_complex(
        np.array([rho * np.exp(1j * phi), rho * np.exp(-1j * phi)])
    )
    assert np.allclose(_roots(a), expected, atol=1e-12)


def test_overdamped_section_has_two_real_poles():
    ts, f, zeta = 0.002, 30.0, 2.0
    wt = 2 * np.pi * f * ts
    p1 = np.exp((-zeta + np.sqrt(zeta**2 - 1)) * wt)
    p2 = np.exp((-zeta - np.sqrt(zeta**2 - 1)) * wt)
    a = ModalParametrization(2, ts).to_denominator([f, np.log10(zeta)])
    assert a == pytest.approx([-(p1 + p2), p1 * p2], rel=1e-13)


def test_critically_damped_section_is_continuous():
    par = ModalParametrization(2, 0.01)
    below = par.to_denominator([5.0, -1e-9])
    above = par.to_denominator([5.0, 1e-9])
    assert below == pytest.approx(above, abs=1e-8)


def test_sections_multiply_with_first_order_poles():
    # na = 5: two modes and one real pole; the roots are the union.
    ts = 0.002
    par = ModalParametrization(5, ts)
    assert (par.n_sections, par.n_real) == (2, 1)
    x = [13.0, 65.0, np.log10(0.02), np.log10(0.3), -0.4]
    poles = [-0.4 + 0j]
    for f, zeta in ((13.0, 0.02), (65.0, 0.3)):
        wn = 2 * np.pi * f
        s = -zeta * wn + 1j * wn * np.sqrt(1 - zeta**2)
        poles += [np.exp(s * ts), np.exp(np.conj(s) * ts)]
    assert np.allclose(
        _roots(par.to_denominator(x)), np.sort_complex(poles), atol=1e-12
    )


def test_every_point_of_the_box_is_stable_and_maps_back():
    for na, real in ((8, 0), (7, 1), (6, 2), (3, 3)):
        par = ModalParametrization(na, 0.002, real_poles=real)
        x = par.initial_points(500, rng=na)
        a = par.to_denominator(x)
        assert is_stable_polynomial(a).all()
        for row in a[:100]:
            back = par.to_denominator(par.from_denominator(row))
            assert back == pytest.approx(row, abs=1e-10)


def test_corners_of_a_section_box_are_stable():
    # (A fourfold repetition of the slowest, lightest mode is a pole of
    # multiplicity 4 within 3e-6 of z = 1: rounding in the coefficients can
    # then fail the Schur-Cohn test; one section at each corner is exact.)
    par = ModalParametrization(2, 0.002)
    lo, hi = par.bounds[:, 0], par.bounds[:, 1]
    corners = np.array([[lo[0], lo[1]], [lo[0], hi[1]], [hi[0], lo[1]], [hi[0], hi[1]]])
    assert is_stable_polynomial(par.to_denominator(corners)).all()


def test_from_denominator_reflects_unstable_poles():
    # Poles 1.25 e^{+-j 0.3}: reflected to 0.8 e^{+-j 0.3}.
    z = 1.25 * np.exp(1j * 0.3)
    a = np.real(np.poly([z, np.conj(z)]))[1:]
    par = ModalParametrization(2, 1.0)
    got = _roots(par.to_denominator(par.from_denominator(a)))
    want = np.sort_complex(np.array([0.8 * np.exp(1j * 0.3), 0.8 * np.exp(-1j * 0.3)]))
    assert np.allclose(got, want, atol=1e-12)


def test_jacobian_matches_the_analytic_derivative_of_c2():
    # c2 = exp(-2 zeta wn ts) and zeta = 10^x: d c2 / dx = -2 wn ts ln(10) zeta c2.
    ts, f, lz = 0.01, 7.0, -1.2
    par = ModalParametrization(2, ts)
    jac = par.jacobian([f, lz])
    zeta, wt = 10**lz, 2 * np.pi * f * ts
    c2 = np.exp(-2 * zeta * wt)
    assert jac[1, 1] == pytest.approx(-2 * wt * np.log(10) * zeta * c2, rel=1e-6)
    assert jac[1, 0] == pytest.approx(-2 * zeta * 2 * np.pi * ts * c2, rel=1e-6)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(na=0, ts=1.0), "`na`"),
        (dict(na=4, ts=-1.0), "`ts`"),
        (dict(na=4, ts=1.0, real_poles=1), "`real_poles`"),
        (dict(na=4, ts=1.0, real_poles=6), "`real_poles`"),
        (dict(na=4, ts=1.0, log_damping=(1.0, -1.0)), "`log_damping`"),
    ],
)
def test_bad_arguments_are_named(kwargs, match):
    with pytest.raises(ValueError, match=match):
        ModalParametrization(**kwargs)


def test_bad_coordinates_are_named():
    par = ModalParametrization(4, 1.0)
    with pytest.raises(ValueError, match="`x`"):
        par.to_denominator([1.0, 2.0])
    with pytest.raises(ValueError, match="`a`"):
        par.from_denominator([np.nan, 0.0, 0.0, 0.0])


@pytest.mark.parametrize("na", [10, 16, 24, 32])
def test_many_real_poles_are_paired_by_a_rule_not_by_enumeration(monkeypatch, na):
    # (na - 1)!! pairings of na real poles (2 million at 16) were once all
    # examined: now two pairings of na / 2 pairs each.
    par = ModalParametrization(na, ts=0.002)
    calls = []
    original = par._mode_of_real_pair
    monkeypatch.setattr(
        par, "_mode_of_real_pair", lambda pair: calls.append(1) or original(pair)
    )
    x = par.from_denominator(np.zeros(na))
    assert len(calls) <= na
    # The zero model (all poles at z = 0) maps to the box's nearest
    # representable point: every section a double pole at exp(-pi), the
    # fastest critically damped mode, with its frequency at the box's edge.
    s = par.n_sections
    np.testing.assert_allclose(x[:s], par.bounds[0, 1])
    np.testing.assert_allclose(x[s : 2 * s], 0.0, atol=1e-2)


@pytest.mark.parametrize("na", [10, 16])
def test_repeated_real_poles_round_trip(na):
    # Overdamped sections built in the box, several of them equal: the
    # denominator maps back to one with the same poles.
    par = ModalParametrization(na, ts=0.002)
    s = par.n_sections
    freqs = np.r_[[20.0] * (s // 2), [60.0] * (s - s // 2)]
    logz = np.r_[[0.3] * (s // 2), [0.1] * (s - s // 2)]
    a = par.to_denominator(np.r_[freqs, logz])
    back = par.to_denominator(par.from_denominator(a))
    np.testing.assert_allclose(back, a, rtol=1e-6, atol=1e-9)
