"""The rig grey box's input delay against independent references: a delay
of whole samples is the input shifted; a fractional delay or an advance is
SciPy's continuous simulation (``signal.lsim``, zero-order hold) of the
delayed held input on a fine grid; the proper discrete model has the same
run; a record made with a delay gives it back; off by default; bad values
refused in one line."""

import dataclasses

import numpy as np
import pytest
from scipy import signal

import spiralid as sid
from spiralid.choices import RIG_PARAMETERS
from spiralid.cli.rig import _free_fields
from spiralid.fms import FlexibleManipulator, Sensors, nonlinear_rig
from spiralid.fms._zoh import delay_split, discretise_delayed
from spiralid.fms.greybox import DELAY, RigGreyBox, default_parameter
from spiralid.sysid import Parameter, load_model

TS = 0.01
RIG = FlexibleManipulator(n_elements=4)


def _boxes():
    kw = dict(output="end_acceleration", sensors=Sensors.ideal(), n_modes=3)
    delayed = RigGreyBox(["hub_inertia", DELAY], RIG, **kw)
    plain = RigGreyBox(["hub_inertia"], RIG, **kw)
    return delayed, plain


def _torque(n=300):
    return np.random.default_rng(0).standard_normal(n)


@pytest.mark.parametrize("samples", [0, 1, 3])
def test_a_whole_sample_delay_is_the_input_shifted(samples):
    delayed, plain = _boxes()
    u = _torque()
    values = [RIG.hub_inertia, samples * TS]
    shifted = np.r_[np.zeros(samples), u[: u.size - samples]]
    np.testing.assert_allclose(
        delayed.simulate(values, u, TS),
        plain.simulate([RIG.hub_inertia], shifted, TS),
        rtol=0,
        atol=1e-12 * np.max(np.abs(plain.simulate([RIG.hub_inertia], u, TS))),
    )


@pytest.mark.parametrize("share", [0.37, -0.43, 1.55])
def test_a_fractional_delay_or_advance_is_scipys_run_of_the_shifted_hold(share):
    delayed, _ = _boxes()
    u = _torque()
    values = [RIG.hub_inertia, share * TS]
    a, b, c, d = delayed.matrices(values, TS)
    fine = 100  # the delay is a whole number of fine steps
    held = np.repeat(u, fine)
    shift = round(share * fine)
    if shift >= 0:
        moved = np.r_[np.zeros(shift), held[: held.size - shift]]
    else:
        moved = np.r_[held[-shift:], np.repeat(u[-1], -shift)]
    t = np.arange(held.size) * TS / fine
    _, y_fine, _ = signal.lsim((a, b, c, d), moved, t, interp=False)
    reference = y_fine[::fine]
    y = delayed.simulate(values, u, TS)
    scale = np.max(np.abs(reference))
    np.testing.assert_allclose(y, reference, rtol=0, atol=1e-9 * scale)
    # The proper discrete model (for the transfer function and the poles)
    # runs the same: from rest, except an advance's state x - G0 u[n].
    ad, bd, cd, dd = delayed.discretise(values, TS)
    x0 = np.zeros(ad.shape[0])
    if share < 0:
        x0 = -discretise_delayed(a, b[:, 0], TS, share * TS)[1] * u[0]
    _, y_proper, _ = signal.dlsim((ad, bd, cd, dd, TS), u, x0=x0)
    np.testing.assert_allclose(y_proper[:, 0], y, rtol=0, atol=1e-9 * scale)


def test_the_delay_is_off_unless_named_and_zero_changes_nothing():
    delayed, plain = _boxes()
    u = _torque()
    assert plain.delay_at(plain.initial_values) is None
    assert delayed.initial_values[1] == 0.0
    np.testing.assert_allclose(
        delayed.simulate(delayed.initial_values, u, TS),
        plain.simulate(plain.initial_values, u, TS),
        rtol=1e-12,
        atol=1e-12,
    )
    assert default_parameter(RIG, DELAY).bounds == (-0.01, 0.01)
    assert RIG_PARAMETERS[DELAY] == "s"
    assert _free_fields("hub_inertia,input_delay") == ["hub_inertia", DELAY]


def test_a_record_made_with_an_advance_gives_it_back_and_reads_back():
    truth = -0.0043
    delayed, _ = _boxes()
    u = _torque(400)
    y = delayed.simulate([RIG.hub_inertia * 1.3, truth], u, TS)
    data = sid.IOData(u, y, ts=TS)
    start = RigGreyBox(
        ["hub_inertia", Parameter(DELAY, 0.0, (-0.009, 0.009), "s")], RIG,
        output="end_acceleration", sensors=Sensors.ideal(), n_modes=3,
    )  # fmt: skip
    model = sid.identify(data, start, method="oe")
    np.testing.assert_allclose(model.values, [RIG.hub_inertia * 1.3, truth], rtol=1e-6)
    again = load_model(model.to_dict())
    assert again.structure.delay_at(again.values) == pytest.approx(truth, rel=1e-6)
    np.testing.assert_allclose(again.simulate(data), model.simulate(data), rtol=1e-12)


def test_a_delay_adds_no_zero_and_keeps_scipys_transfer_function():
    # A delay of whole samples only multiplies the transfer function by
    # z^-k: the finite zeros are the undelayed model's, none of them a
    # rounding root near 1e16.
    delayed, _ = _boxes()
    u = _torque(200)
    y = delayed.simulate([RIG.hub_inertia, 0.0], u, TS)
    fitted = sid.identify(sid.IOData(u, y, ts=TS), delayed, method="oe")
    at = {k: dataclasses.replace(fitted, values=np.array([RIG.hub_inertia, k * TS]))
          for k in (0, 1, 2, 0.37)}  # fmt: skip
    plain = np.sort_complex(at[0].zeros)
    for k in (1, 2):
        np.testing.assert_allclose(np.sort_complex(at[k].zeros), plain, rtol=1e-8)
        num, den = at[k].polynomials
        np.testing.assert_array_equal(num[:k], 0.0)
        scale = np.max(np.abs(num))
        head = at[0].polynomials[0][: num.size - k]
        np.testing.assert_allclose(num[k:], head, rtol=1e-9, atol=1e-12 * scale)
    # A fractional delay's numerator is SciPy's to rounding, its zeros finite.
    assert np.max(np.abs(at[0.37].zeros)) < 10.0
    ad, bd, c, d = delayed.discretise(at[0.37].values, TS)
    num, den = signal.ss2tf(ad, bd, c, d)
    np.testing.assert_allclose(at[0.37].polynomials[0], num[0],
                               atol=1e-10 * np.max(np.abs(num)))  # fmt: skip
    np.testing.assert_allclose(at[0.37].polynomials[1], den, rtol=1e-12)


def test_bad_delays_are_refused_in_one_line():
    delayed, _ = _boxes()
    # An advance of a whole sample would need later inputs: the penalty.
    assert np.all(np.isnan(delayed.simulate([RIG.hub_inertia, -TS], _torque(), TS)))
    with pytest.raises(ValueError, match="above -ts"):
        delay_split(-1.5 * TS, TS)
    with pytest.raises(ValueError, match="input_delay needs the linear rig"):
        RigGreyBox([DELAY], nonlinear_rig())
