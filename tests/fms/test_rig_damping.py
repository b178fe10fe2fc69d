"""The rig's Rayleigh damping against independent references: each flexible
mode's ratio is ``alpha / (2 w) + beta w / 2`` on the finite elements' own
modes (SciPy's generalised eigenproblem of K and M); the damping matrix is
``alpha M + beta K`` without its rigid share; the model's poles are the
damped modes'; zero coefficients give today's one-ratio model; a record
made with Rayleigh damping gives it back; the start from modes gives each
mode its damping; bad values refused in one line."""

import dataclasses
import json
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.linalg import eigh

import spiralid as sid
from spiralid.choices import RIG_PARAMETERS
from spiralid.cli.rig import _free_fields
from spiralid.fms import FlexibleManipulator, Sensors
from spiralid.fms.greybox import RigGreyBox, default_parameter
from spiralid.fms.greybox_start import rig_start_from_modes
from spiralid.sysid import Parameter, load_model

TS = 0.01
ALPHA, BETA = 0.8, 2e-4


def _fem_modes(rig):
    """Natural frequencies (rad/s) and mass-normalised modes of the full
    generalised problem ``K v = w^2 M v`` (the rigid one first)."""
    lam, v = eigh(rig.stiffness_matrix, rig.mass_matrix)
    return np.sqrt(np.clip(lam, 0.0, None)), v


def test_each_modes_ratio_is_rayleighs_on_the_fems_own_modes():
    rig = FlexibleManipulator(
        n_elements=4, damping_ratio=0.0, mass_damping=ALPHA, stiffness_damping=BETA
    )
    w, _ = _fem_modes(rig)
    flexible = w[1:]
    np.testing.assert_allclose(
        rig.mode_damping(), ALPHA / (2 * flexible) + BETA * flexible / 2, rtol=1e-9
    )
    # With the one ratio on top, the two add.
    both = FlexibleManipulator(
        n_elements=4, damping_ratio=0.01, mass_damping=ALPHA, stiffness_damping=BETA
    )
    np.testing.assert_allclose(
        both.mode_damping(), 0.01 + rig.mode_damping(), rtol=1e-12
    )


def test_the_damping_matrix_is_alpha_m_plus_beta_k_without_its_rigid_share():
    rig = FlexibleManipulator(
        n_elements=4, damping_ratio=0.0, mass_damping=ALPHA, stiffness_damping=BETA
    )
    m, k = rig.mass_matrix, rig.stiffness_matrix
    # The rigid mode is the hub angle alone, mass-normalised: e0 / sqrt(J).
    rigid = m[:, 0] / np.sqrt(m[0, 0])
    expected = ALPHA * m + BETA * k - ALPHA * np.outer(rigid, rigid)
    np.testing.assert_allclose(
        rig.damping_matrix, expected, rtol=0, atol=1e-10 * np.abs(expected).max()
    )
    # Diagonal on SciPy's modes: alpha + beta w^2, zero for the rigid one.
    w, v = _fem_modes(rig)
    modal = v.T @ rig.damping_matrix @ v
    want = np.r_[0.0, ALPHA + BETA * w[1:] ** 2]
    np.testing.assert_allclose(
        modal, np.diag(want), rtol=0, atol=1e-9 * np.abs(want).max()
    )


def test_the_models_poles_are_the_damped_modes():
    rig = FlexibleManipulator(
        n_elements=4, damping_ratio=0.0, mass_damping=ALPHA, stiffness_damping=BETA
    )
    box = RigGreyBox(["hub_inertia"], rig, output="hub_angle", n_modes=3)
    poles = np.linalg.eigvals(box.matrices(box.initial_values, TS)[0])
    upper = poles[poles.imag > 0]
    upper = upper[np.argsort(upper.imag)]
    w, _ = _fem_modes(rig)
    w = w[1:4]
    z = ALPHA / (2 * w) + BETA * w / 2
    np.testing.assert_allclose(
        upper, -z * w + 1j * w * np.sqrt(1 - z**2), rtol=1e-8
    )  # fmt: skip


def test_zero_coefficients_give_todays_one_ratio_model():
    rig = FlexibleManipulator(n_elements=4, damping_ratio=0.03)
    w, v = _fem_modes(rig)
    # Today's modal damping from SciPy's modes: M V diag(2 z w) V^T M.
    mv = rig.mass_matrix @ v
    expected = (mv * (2 * 0.03 * w)) @ mv.T
    np.testing.assert_allclose(
        rig.damping_matrix, expected, rtol=0, atol=1e-10 * np.abs(expected).max()
    )
    np.testing.assert_array_equal(rig.mode_damping(), np.full(8, 0.03))
    kw = dict(output="end_acceleration", sensors=Sensors.ideal(), n_modes=3)
    one = RigGreyBox(["damping_ratio"], rig, **kw)
    rayleigh = ["damping_ratio", "mass_damping", "stiffness_damping"]
    three = RigGreyBox(rayleigh, rig, **kw)
    u = np.random.default_rng(0).standard_normal(200)
    np.testing.assert_array_equal(
        three.simulate([0.03, 0.0, 0.0], u, TS), one.simulate([0.03], u, TS)
    )


def test_a_record_with_rayleigh_damping_gives_it_back_and_reads_back(tmp_path):
    base = FlexibleManipulator(n_elements=4, damping_ratio=0.0)
    kw = dict(output="end_acceleration", sensors=Sensors.ideal(), n_modes=3)
    truth = RigGreyBox(["mass_damping", "stiffness_damping"], base, **kw)
    u = np.random.default_rng(1).standard_normal(600)
    data = sid.IOData(u, truth.simulate([2.0, 4e-4], u, TS), ts=TS)
    start = RigGreyBox(
        [Parameter("mass_damping", 1.0, (0.0, 10.0), "1/s"),
         Parameter("stiffness_damping", 1e-4, (0.0, 2e-3), "s")],
        base, **kw,
    )  # fmt: skip
    model = sid.identify(data, start, method="oe")
    np.testing.assert_allclose(model.values, [2.0, 4e-4], rtol=1e-5)
    path = tmp_path / "model.json"
    path.write_text(json.dumps(model.to_dict()))
    again = load_model(path)
    np.testing.assert_array_equal(again.simulate(data), model.simulate(data))
    # The modes' table lists each mode's own ratio.
    table = again.structure.modes_beside(again.values, 2).splitlines()
    fitted = again.structure.rig_at(again.values).mode_damping(2)
    assert [float(row.split()[-1]) for row in table[1:]] == pytest.approx(
        fitted, abs=1e-4
    )


def test_the_fields_are_in_the_one_list_with_bounds_and_on_the_command_line():
    rig = FlexibleManipulator(n_elements=4)
    w1 = 2 * np.pi * rig.modes(1)[0]
    assert RIG_PARAMETERS["mass_damping"] == "1/s"
    assert RIG_PARAMETERS["stiffness_damping"] == "s"
    assert default_parameter(rig, "mass_damping").bounds == pytest.approx((0, w1))
    assert default_parameter(rig, "stiffness_damping").bounds == pytest.approx(
        (0, 1 / w1)
    )
    assert _free_fields("mass_damping,stiffness_damping") == [
        "mass_damping",
        "stiffness_damping",
    ]


@pytest.mark.parametrize("field", ["mass_damping", "stiffness_damping"])
@pytest.mark.parametrize("value", [-0.1, np.nan, np.inf])
def test_bad_coefficients_are_refused_in_one_line(field, value):
    with pytest.raises(ValueError, match=field) as err:
        FlexibleManipulator(**{field: value})
    assert "\n" not in str(err.value)
    with pytest.raises(TypeError, match=field):
        FlexibleManipulator(**{field: "0.1"})


def test_the_start_from_modes_gives_each_mode_its_damping():
    base = FlexibleManipulator(n_elements=4, damping_ratio=0.002)
    truth = dataclasses.replace(base, mass_damping=ALPHA, stiffness_damping=BETA)
    table = SimpleNamespace(
        frequency=truth.modes(2), damping=truth.mode_damping(2), spurious=[0, 0]
    )
    box = RigGreyBox(
        ["hub_inertia", "mass_damping", "stiffness_damping"], base, n_modes=2
    )
    start = rig_start_from_modes(box, table, rng=0)
    np.testing.assert_allclose(start.initial_values[1:], [ALPHA, BETA], rtol=1e-8)
    # A held ratio above the modes' damping: the coefficients stop at zero.
    high = dataclasses.replace(base, damping_ratio=0.5)
    box = RigGreyBox(["hub_inertia", "mass_damping"], high, n_modes=2)
    assert rig_start_from_modes(box, table, rng=0).initial_values[1] == 0.0
