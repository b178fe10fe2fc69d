"""The rig's nonlinearities: off by default, friction dissipates as its law says."""

import numpy as np
import pytest

from spiralid.fms import FlexibleManipulator, Sensors, nonlinear_rig, paper_experiment


def _energy(rig, state):
    n = rig.ndof
    q, v = state[:, :n], state[:, n:]
    M, K = rig.mass_matrix, rig.stiffness_matrix
    return 0.5 * np.einsum("ti,ij,tj->t", v, M, v) + 0.5 * np.einsum(
        "ti,ij,tj->t", q, K, q
    )


def test_everything_off_is_bit_identical_to_the_linear_rig():
    u = paper_experiment().torque()
    plain = FlexibleManipulator().simulate(u, rng=3, return_state=True)
    off = FlexibleManipulator(
        coulomb_friction=0.0, static_friction=0.0, torque_limit=None
    ).simulate(u, rng=3, return_state=True)
    # A limit no sample reaches clips nothing: the same floats.
    wide = FlexibleManipulator(torque_limit=1e6).simulate(u, rng=3, return_state=True)
    for name in ("u", "hub_angle", "hub_velocity", "end_acceleration", "state"):
        np.testing.assert_array_equal(getattr(plain, name), getattr(off, name))
        np.testing.assert_array_equal(getattr(plain, name), getattr(wide, name))


def test_saturation_is_the_clipped_torque():
    u = np.r_[np.full(200, 0.5), np.full(200, -0.1), np.zeros(600)]
    sat = FlexibleManipulator(torque_limit=0.2).simulate(u)
    ref = FlexibleManipulator().simulate(np.clip(u, -0.2, 0.2))
    np.testing.assert_array_equal(sat.hub_angle, ref.hub_angle)
    np.testing.assert_array_equal(sat.u, u)  # the record keeps the command


def test_coulomb_friction_dissipates_its_torque_times_the_travel():
    """No input, no other damping, the hub launched at 0.5 rad/s: the energy
    lost equals Fc times the hub's total travel (work of a constant-magnitude
    torque opposing the motion), and never rises."""
    fc = 0.01
    rig = FlexibleManipulator(damping_ratio=0.0, coulomb_friction=fc)
    fs = 5000.0
    x0 = np.zeros(2 * rig.ndof)
    x0[rig.ndof] = 0.5
    rec = rig.simulate(
        np.zeros(20000), fs=fs, sensors=Sensors.ideal(), x0=x0, return_state=True
    )
    e = _energy(rig, rec.state)
    travel = np.sum(np.abs(np.diff(rec.state[:, 0])))
    # While the hub sticks, the holding torque trades ~1e-12 of the energy
    # with the beam within a sub-step; it never adds energy beyond that.
    assert np.all(np.diff(e) <= 1e-9 * e[0])
    assert e[0] - e[-1] == pytest.approx(fc * travel, rel=0.02)
    # The rigid estimate (J v0^2 / 2 = Fc theta) says the hub travels ~0.5 m rad
    # before sticking; it has stopped well before the end.
    assert abs(rec.state[-1, rig.ndof]) < 1e-6
    assert travel == pytest.approx(rig.total_inertia * 0.25 / (2 * fc), rel=0.1)


def test_torque_below_breakaway_leaves_the_hub_at_rest():
    rig = FlexibleManipulator(coulomb_friction=0.02, static_friction=0.03)
    rec = rig.simulate(np.full(500, 0.025), sensors=Sensors.ideal())
    assert np.max(np.abs(rec.hub_angle)) < 1e-9
    moving = rig.simulate(np.full(500, 0.04), sensors=Sensors.ideal())
    assert moving.hub_angle[-1] > 1e-3


def test_nonlinear_rig_preset_and_bad_values():
    rig = nonlinear_rig(torque_limit=0.5)
    assert rig.has_friction and rig.torque_limit == 0.5
    with pytest.raises(ValueError, match="`coulomb_friction` must be"):
        FlexibleManipulator(coulomb_friction=-1.0)
    with pytest.raises(ValueError, match="`torque_limit` must be"):
        FlexibleManipulator(torque_limit=0.0)
    with pytest.raises(ValueError, match="`friction_substeps` must be"):
        FlexibleManipulator(friction_substeps=0)
    with pytest.raises(ValueError, match="`stribeck_velocity` must be"):
        FlexibleManipulator(stribeck_velocity=float("nan"))


def test_friction_run_is_reproducible_and_fast_path_shape():
    rig = nonlinear_rig()
    u = np.sin(np.arange(1500) / 50.0) * 0.3
    a = rig.simulate(u, rng=1, sensors=Sensors(accel_noise=0.1))
    b = rig.simulate(u, rng=1, sensors=Sensors(accel_noise=0.1))
    np.testing.assert_array_equal(a.end_acceleration, b.end_acceleration)
    assert a.state is None and a.hub_angle.shape == (1500,)
