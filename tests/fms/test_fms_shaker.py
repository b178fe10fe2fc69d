"""The rig's second actuator: a shaker's point force on the beam
(`FlexibleManipulator.load_vector`, `simulate(force=, force_at=)`,
`Experiment.force_at`)."""

from dataclasses import replace

import numpy as np
import pytest

from spiralid.fms import (
    FlexibleManipulator,
    Sensors,
    bang_bang,
    nonlinear_rig,
    paper_experiment,
)


def _cantilever(x, a, length, ei):
    """The analytic deflection of a cantilever of `length` under a unit
    point load at `a` (Euler-Bernoulli): ``x^2 (3a - x) / (6 EI)`` before
    the load, ``a^2 (3x - a) / (6 EI)`` beyond it."""
    x = np.asarray(x) * length
    a = a * length
    return np.where(x <= a, x**2 * (3 * a - x), a**2 * (3 * x - a)) / (6 * ei)


@pytest.mark.parametrize("at", [0.63, 0.6, 1.0])
def test_the_load_vector_bends_a_clamped_beam_as_the_analytic_cantilever(at):
    rig = FlexibleManipulator()
    load = rig.load_vector(at)
    # The hub held fixed: the beam alone is a cantilever under the load.
    w = np.linalg.solve(rig.stiffness_matrix[1:, 1:], load[1:])
    q = np.r_[0.0, w]
    # Hermite elements with the consistent load are exact at the nodes and
    # in every element that does not hold the load (the exact deflection is
    # cubic there); the loaded element's interior is not checked.
    n = rig.n_elements
    loaded = min(int(at * n), n - 1)
    nodes = np.arange(1, n + 1) / n
    inside = np.array(
        [(e + f) / n for e in range(n) if e != loaded for f in (0.3, 0.7)]
    )
    x = np.r_[nodes, inside]
    exact = _cantilever(x, at, rig.length, rig.flexural_rigidity)
    np.testing.assert_allclose(rig.deflection_rows(x) @ q, exact, rtol=1e-9)
    # The hub's entry is the force's moment about the axis.
    assert load[0] == pytest.approx(at * rig.length)


def test_a_force_and_an_accelerometer_are_reciprocal():
    # Maxwell-Betti: the force at x1 seen by an accelerometer at x2 is the
    # force at x2 seen at x1 (symmetric mass, stiffness and modal damping).
    rig = FlexibleManipulator()
    u = np.zeros(800)
    f = bang_bang(1.0, 0.02, 0.01, 1.6, 500.0)
    one = rig.simulate(
        u, sensors=Sensors.ideal(acceleration_at=(0.8,)), force=f, force_at=0.35
    )
    two = rig.simulate(
        u, sensors=Sensors.ideal(acceleration_at=(0.35,)), force=f, force_at=0.8
    )
    scale = np.abs(one.acceleration).max()
    np.testing.assert_allclose(one.acceleration, two.acceleration, atol=1e-9 * scale)
    assert scale > 0


def test_a_force_at_the_tip_against_the_torque_moves_no_rigid_body():
    # A force F at the tip and a torque -F L at the hub have no net moment:
    # the hub's angle only vibrates about zero, where the torque alone
    # would turn the hub for good.
    rig = FlexibleManipulator()
    f = bang_bang(1.0, 0.05, 0.0, 2.0, 500.0)
    f[f < 0] = 0.0
    alone = rig.simulate(-rig.length * f, sensors=Sensors.ideal())
    both = rig.simulate(-rig.length * f, sensors=Sensors.ideal(), force=f, force_at=1.0)
    assert abs(alone.hub_angle[-200:].mean()) > 0.01
    assert abs(both.hub_angle[-200:].mean()) < 1e-3 * abs(alone.hub_angle[-200:].mean())


def test_without_a_force_the_record_is_as_before():
    rig = FlexibleManipulator()
    u = bang_bang(0.3, 0.04, 0.1, 1.0, 500.0)
    plain = rig.simulate(u, rng=0)
    zero = rig.simulate(u, rng=0, force=np.zeros_like(u), force_at=0.6)
    assert plain.force is None and plain.input_names == ("torque",)
    np.testing.assert_array_equal(zero.end_acceleration, plain.end_acceleration)
    assert zero.input_names == ("torque", "force") and zero.force_at == 0.6
    d = zero.iodata(["end_acceleration", "hub_velocity"], input="force")
    assert (d.input_name, d.input_unit) == ("force", "N")
    with pytest.raises(ValueError, match="`input` must be one of"):
        plain.iodata(input="force")
    both = zero.iodata("end_acceleration", input=["torque", "force"])
    assert both.input_names == ("torque", "force")
    assert both.input_units == ("N m", "N")
    np.testing.assert_array_equal(both.u, np.column_stack([zero.u, zero.force]))
    with pytest.raises(ValueError, match="each input once"):
        zero.iodata(input=["force", "force"])


def test_the_shaker_refuses_bad_input_in_one_line():
    rig = FlexibleManipulator()
    u = np.zeros(10)
    with pytest.raises(ValueError, match="`force` needs `force_at`"):
        rig.simulate(u, force=u)
    with pytest.raises(ValueError, match="`force_at` needs a `force`"):
        rig.simulate(u, force_at=0.5)
    with pytest.raises(ValueError, match="as many samples as `torque` \\(10\\)"):
        rig.simulate(u, force=np.zeros(9), force_at=0.5)
    with pytest.raises(ValueError, match="`force_at` must be a fraction"):
        rig.simulate(u, force=u, force_at=1.5)
    with pytest.raises(TypeError, match="`force_at` must be a fraction"):
        rig.simulate(u, force=u, force_at="tip")
    with pytest.raises(ValueError, match="`force` must be finite"):
        rig.simulate(u, force=np.r_[np.nan, u[1:]], force_at=0.5)
    with pytest.raises(ValueError, match="hub friction"):
        nonlinear_rig().simulate(u, force=u, force_at=0.5)
    with pytest.raises(ValueError, match="`position` must be a fraction"):
        rig.load_vector(0.0)


def test_the_experiment_adds_a_shaker_half_a_period_after_each_torque_pulse():
    exp = replace(paper_experiment(), force_at=0.6, acceleration_at=(0.3,))
    rec = exp.run(rng=0)
    assert rec.force_at == 0.6
    np.testing.assert_array_equal(rec.force, exp.force())
    # The torque's and the force's pulses never overlap.
    assert not np.any((exp.torque() != 0) & (exp.force() != 0))
    # The outputs hold both inputs' responses: the torque's alone differ.
    alone = paper_experiment().run(rng=0)
    assert not np.allclose(rec.hub_velocity, alone.hub_velocity)
    assert paper_experiment().force() is None
    with pytest.raises(ValueError, match="`force_at` must be a fraction"):
        replace(paper_experiment(), force_at=-0.1)
    with pytest.raises(ValueError, match="`force_amplitude` must be a finite"):
        replace(paper_experiment(), force_at=0.6, force_amplitude=np.nan)


@pytest.mark.parametrize("force_at", [None, 0.6])
def test_the_rigs_residues_are_the_fems_shapes_at_the_sensors(force_at):
    # The reference the mode shapes are compared with: the exact sampled
    # rig's residues at each mode's pole, over accelerometers (through the
    # anti-aliasing filter) and deflection sensors, are the FEM's inertial
    # and hub-frame shapes at their positions up to one complex factor,
    # from the torque and from the shaker alike.
    from spiralid.fms.rig import _discrete
    from spiralid.sysid.models.shapes import mac

    rig = FlexibleManipulator()
    at = (0.25, 0.5, 0.75, 1.0)
    ts = 1 / 500
    Ad, Bd, C, _, _ = _discrete(rig, ts, 4, 0.35, at, at, force_at=force_at)
    lam, vec = np.linalg.eig(Ad)
    left = np.linalg.inv(vec)
    for k, f in enumerate(rig.modes(3), 1):
        pole = np.exp(2 * np.pi * f * ts * (-0.02 + 1j * np.sqrt(1 - 0.02**2)))
        i = int(np.argmin(np.abs(lam - pole)))
        assert abs(lam[i] - pole) < 1e-9
        residues = (C @ vec[:, i]) * (left[i] @ Bd)
        hub = rig.mode_shape(k, at)
        inertial = rig.mode_shape(k, at, frame="inertial")
        assert mac(residues[4:8], hub)[0, 0] == pytest.approx(1.0, abs=1e-10)
        assert mac(residues[8:], inertial)[0, 0] == pytest.approx(1.0, abs=1e-10)
        # Not a MAC that is 1 for anything: the other frame's shape is off.
        assert mac(residues[8:], hub)[0, 0] < 0.999
