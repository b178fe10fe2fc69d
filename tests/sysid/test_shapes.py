"""Mode shapes from residues, their intervals and the MAC
(`sysid/models/shapes.py`, `sysid/estimation/shared/covariance.py`)."""

import json

import numpy as np
import pytest
from scipy import signal
from two_modes import TS, A, B, record

from spiralid.sysid import ARX, identify
from spiralid.sysid.models.polynomials import with_integrator
from spiralid.sysid.models.shapes import (
    mac,
    mode_shapes,
    normalise_shapes,
    output_residues,
    residue_gradient,
)


def test_mac_of_hand_worked_shapes():
    # [1, 2] . [2, 1] = 4; |.|^2 = 16 over 5 * 5.
    assert mac([1.0, 2.0], [2.0, 1.0])[0, 0] == pytest.approx(16 / 25, abs=1e-15)
    # [1, i]^H [1, 0] = 1, over 2 * 1.
    assert mac([1.0, 1j], [1.0, 0.0])[0, 0] == pytest.approx(0.5, abs=1e-15)
    # [i, -1] = i [1, i]: the same shape up to a complex factor.
    assert mac([1.0, 1j], [1j, -1.0])[0, 0] == pytest.approx(1.0, abs=1e-15)
    # Orthogonal shapes, and the auto-MAC of a set.
    auto = mac([[1.0, 1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 0.0, 0.0]])
    np.testing.assert_allclose(
        auto, [[1, 0, 0.5], [0, 1, 0.5], [0.5, 0.5, 1]], atol=1e-15
    )


def test_mac_refuses_bad_shapes_in_one_line():
    with pytest.raises(ValueError, match="`shapes_b` must have as many components"):
        mac([1.0, 2.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="nonzero component"):
        mac([0.0, 0.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="`shapes_a` must be a non-empty finite"):
        mac([np.nan, 1.0])
    with pytest.raises(TypeError, match="`shapes_a` must be an array of numbers"):
        mac(["a", "b"])


def test_normalised_shapes_have_unit_norm_and_a_real_positive_largest_part():
    rng = np.random.default_rng(0)
    phi = rng.standard_normal((3, 5)) + 1j * rng.standard_normal((3, 5))
    psi = normalise_shapes(phi)
    np.testing.assert_allclose(np.linalg.norm(psi, axis=1), 1.0, rtol=1e-14)
    big = psi[np.arange(3), np.argmax(np.abs(psi), axis=1)]
    np.testing.assert_allclose(big.imag, 0.0, atol=1e-15)
    assert np.all(big.real > 0)
    # Any complex factor gives the same normalised shape.
    np.testing.assert_allclose(normalise_shapes(-2.5j * phi), psi, atol=1e-14)
    np.testing.assert_allclose(np.diag(mac(phi, psi)), 1.0, rtol=1e-14)


@pytest.mark.parametrize("count", [0, 1, 2])
def test_residues_are_scipys_and_their_gradient_the_finite_differences(count):
    rng = np.random.default_rng(count)
    poles = [0.9 * np.exp(0.3j), 0.8 * np.exp(1.1j)]
    a = np.poly([*poles, *np.conj(poles)]).real[1:]
    b = rng.standard_normal((3, 4))
    res, grad = output_residues(a, b, poles, nk=1, integrators=(count,) * 3)
    for i in range(3):
        den = np.r_[1.0, with_integrator(a, count)]
        r, p, _ = signal.residuez(np.r_[0.0, b[i]], den)
        for m, pole in enumerate(poles):
            assert res[m, i] == pytest.approx(r[np.argmin(np.abs(p - pole))], rel=1e-9)

    def at(theta):
        aa = theta[:4]
        roots = np.roots(np.r_[1.0, aa])
        near = [roots[np.argmin(np.abs(roots - pole))] for pole in poles]
        return output_residues(
            aa, theta[4:].reshape(3, 4), near, nk=1, integrators=(count,) * 3
        )[0]

    theta, h = np.r_[a, b.ravel()], 1e-6
    numeric = np.stack(
        [(at(theta + h * e) - at(theta - h * e)) / (2 * h) for e in np.eye(theta.size)],
        axis=-1,
    )
    np.testing.assert_allclose(grad, numeric, atol=1e-7 * np.abs(grad).max())


def test_a_first_order_residue_by_hand():
    # (1 + 2 z^-1) / (1 - 0.5 z^-1) = -4 + 5 / (1 - 0.5 z^-1).
    c, dc_da, dc_db = residue_gradient([-0.5], [1.0, 2.0], 0.5)
    assert c == pytest.approx(5.0)
    # c = b0 + b1 / p with p = -a: dc/db = [1, 1/p], dc/da = b1 / p^2.
    np.testing.assert_allclose(dc_db, [1.0, 2.0])
    np.testing.assert_allclose(dc_da, [8.0])


def test_the_fits_shapes_are_the_true_ones_within_their_intervals():
    truth = mode_shapes(A[1:], B[:, 1:], TS, nk=1, output_names=("near", "far"))
    fit = identify(record(0), ARX(4, 4, 1), method="oe")
    shapes = fit.shapes
    assert shapes.output_names == ("near", "far") and len(shapes) == 2
    np.testing.assert_allclose(shapes.frequency, fit.modes.table.frequency)
    assert np.all(np.diag(shapes.mac(truth.shapes)) > 0.9999)
    # The factor's block of a is the projected covariance of a (the
    # numerators projected out, a different route to the same number).
    full = fit.shape_factor.T @ fit.shape_factor
    np.testing.assert_allclose(full[:4, :4], fit.covariance, rtol=1e-5)
    # Every component within 4 standard errors of the truth.
    for part, se in ((np.real, shapes.real_se), (np.imag, shapes.imag_se)):
        err = np.abs(part(shapes.shapes) - part(truth.shapes))
        assert np.all(err <= 4 * se + 1e-12)
    assert np.isfinite(shapes.real_se).all()
    text = str(shapes)
    assert "near" in text and "+-" in text
    assert len(shapes.to_dict()["modes"]) == 2


def test_least_squares_shapes_have_no_interval():
    fit = identify(record(1), ARX(4, 4, 1), method="ls")
    assert fit.shape_factor is None
    assert np.isnan(fit.shapes.real_se).all()


def test_a_denominator_without_a_complex_pair_has_no_shapes():
    shapes = mode_shapes([-0.5], [[1.0], [2.0]], TS, nk=1)
    assert len(shapes) == 0 and shapes.shapes.shape == (0, 2)
    assert shapes.auto_mac.shape == (0, 0)
    assert str(shapes).startswith("no modes")


def test_mode_shapes_refuse_a_wrong_factor_or_names():
    with pytest.raises(ValueError, match="`factor` must have 12 columns"):
        mode_shapes(A[1:], B[:, 1:], TS, nk=1, factor=np.eye(3))
    with pytest.raises(ValueError, match="`output_names` must name each of the 2"):
        mode_shapes(A[1:], B[:, 1:], TS, nk=1, output_names=("one",))


def test_the_validation_and_the_report_show_the_shapes_and_their_mac():
    from spiralid.report.shared_output import mac_table, shapes_table
    from spiralid.sysid import validate

    est, val = record(6).split(2 / 3)
    fit = identify(est, ARX(4, 4, 1), method="oe")
    v = validate(fit, val, warmup=est)
    assert v.mode_shapes is not None and len(v.mode_shapes) == 2
    text = v.summary()
    assert "Mode shapes over the outputs" in text and "MAC between the modes" in text
    assert "Mode shapes" not in v.summary(modes=False)
    shapes = v.to_dict()["shapes"]
    assert shapes["output_names"] == ["near", "far"]
    np.testing.assert_allclose(shapes["auto_mac"], fit.shapes.auto_mac)
    head, rows = shapes_table(fit.shapes)
    assert head[:2] == ["mode", "frequency (Hz)"] and len(rows) == 2
    assert rows[0][2].startswith(f"{fit.shapes.shapes[0, 0].real:+.3f} +- ")
    head, rows = mac_table([[1.0, 0.5], [0.5, 1.0]])
    assert head == ["MAC", "1", "2"] and rows[1] == ["2", "0.500", "1.000"]


def test_a_model_read_back_keeps_its_shapes_intervals():
    fit = identify(record(2), ARX(4, 4, 1), method="oe")
    back = type(fit).from_dict(json.loads(json.dumps(fit.to_dict())))
    np.testing.assert_array_equal(back.shape_factor, fit.shape_factor)
    for name in ("shapes", "real_se", "imag_se"):
        np.testing.assert_array_equal(
            getattr(back.shapes, name), getattr(fit.shapes, name)
        )
    assert np.isfinite(back.shapes.real_se).all()
    # A hand-edited factor of the wrong size is refused by its name.
    d = fit.to_dict()
    d["shape_factor"] = d["shape_factor"][:-1]
    with pytest.raises(
        ValueError, match="field 'shape_factor' must be an array of 12 x 12"
    ):
        type(fit).from_dict(d)
