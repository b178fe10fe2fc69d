"""A linear rig grey box of the hub angle integrates the torque twice (the
rigid-body rotation): its two poles at z = 1 are the physics', so `validate`
judges it marginally stable by design, as an ARX fit with two known
integrators, instead of unstable with the cost's penalty. An accelerometer
cancels the same poles with zeros."""

import numpy as np
import pytest
from scipy import signal
from test_rig_greybox import FS, VARIANT, record, torque

import spiralid as sid
from spiralid.fms import FlexibleManipulator, Sensors
from spiralid.fms.greybox import RigGreyBox
from spiralid.sysid.models.polynomials import is_stable_polynomial


@pytest.fixture(scope="module")
def hub_angle_fit():
    rec = record(FlexibleManipulator(**VARIANT), "hub_angle")
    box = RigGreyBox(
        ["hub_inertia"], FlexibleManipulator(**VARIANT), output="hub_angle",
        sensors=Sensors.ideal(),
    )  # fmt: skip
    return rec, sid.identify(rec, box, method="oe")


def test_the_rigid_rotation_is_two_integrators(hub_angle_fit):
    rec, model = hub_angle_fit
    a = model.structure.matrices(model.values, rec.ts)[0]
    rigid = int(np.sum(np.abs(np.linalg.eigvals(a)) < 1e-9 * np.abs(a).max()))
    assert rigid == 2
    assert model.integrator == rigid
    # The other poles, and nothing else, are judged (SciPy's polynomial).
    free = model.free_denominator
    assert free.size == model.poles.size - rigid
    assert is_stable_polynomial(free) and model.is_stable


def test_validate_calls_it_marginally_stable_by_design(hub_angle_fit):
    rec, model = hub_angle_fit
    report = sid.validate(model, rec)
    assert report.stable is True and report.integrator == 2
    assert report.max_pole_radius < 1.0
    assert report.fit_percent > 99.0
    assert "marginally stable by design" in str(report)
    # No stability penalty (eq. 3) in the cost of a near-perfect fit.
    assert report.cost < 1.0


def test_the_end_acceleration_cancels_them_with_zeros():
    """The state keeps the rotation whatever the sensor; an accelerometer's
    transfer function cancels it by two zeros at z = 1."""
    rec = record(FlexibleManipulator(**VARIANT), "end_acceleration")
    box = RigGreyBox(
        ["hub_inertia"], FlexibleManipulator(**VARIANT), output="end_acceleration",
        sensors=Sensors.ideal(),
    )  # fmt: skip
    model = sid.identify(rec, box, method="oe")
    assert model.integrator == 2
    assert np.sum(np.abs(model.zeros - 1.0) < 1e-3) == 2
    free = model.poles[np.abs(model.poles - 1.0) > 1e-3]
    np.testing.assert_allclose(
        model.free_denominator, np.real(np.poly(free))[1:], atol=1e-12
    )


def test_two_sensors_list_the_flexible_modes_once():
    """The modes of a two-sensor fit: the finite elements' flexible modes
    (not the rotation at z = 1), each with its larger share of the two
    sensors' tables, flagged only where both flag it."""
    truth = FlexibleManipulator(**VARIANT)
    rec = truth.simulate(torque(), fs=FS, sensors=Sensors.ideal())
    data = rec.iodata(["hub_angle", "end_acceleration"])
    box = RigGreyBox(
        ["hub_inertia"], FlexibleManipulator(**VARIANT),
        output=("hub_angle", "end_acceleration"), sensors=Sensors.ideal(),
    )  # fmt: skip
    model = sid.identify(data, box, method="oe")
    table = model.modes
    fem = truth.modes(4)
    for f in fem:
        assert np.min(np.abs(table.frequency - f)) < 1e-6 * f
    assert table.frequency.min() > 0.5 * fem[0]
    each = [model.output_model(name).modes for name in data.output_name]
    np.testing.assert_array_equal(table.share, np.maximum(*(t.share for t in each)))
    np.testing.assert_array_equal(table.spurious, each[0].spurious & each[1].spurious)
    # Each sensor has its own numerator: the model of both names neither.
    for member in ("polynomials", "zeros"):
        with pytest.raises(ValueError, match=f"output_model\\(name\\).{member}"):
            getattr(model, member)
    hub = model.output_model("hub_angle")
    c = model.structure.matrices(model.values, rec.ts)[2][:1]
    ad, bd, _, d = model.structure.discretise(model.values, rec.ts)
    num, den = signal.ss2tf(ad, bd, c, d[:1])
    np.testing.assert_allclose(hub.polynomials[0], num[0], atol=1e-12)
    np.testing.assert_allclose(hub.polynomials[1], den, atol=1e-12)
