"""The rig grey box's connection to a record made elsewhere: the output
gain, the modal initial state (against the rig's own simulation from the
same state in generalised coordinates), and the start from a black box's
modes (the start's finite-element frequencies against the truth's, the
gain and state by least squares against the truth's)."""

import dataclasses
import json

import numpy as np
import pytest

import spiralid as sid
from spiralid.fms import FlexibleManipulator, Sensors
from spiralid.fms.greybox import GAIN, RigGreyBox
from spiralid.fms.greybox_start import rig_start_from_modes
from spiralid.sysid import ARX, IOData, Parameter, identify

# A small rig (4 elements): quick exact runs.
SMALL = FlexibleManipulator(n_elements=4, payload_mass=0.03, hub_inertia=8e-4)
TS = 0.01


def torque(n=600, seed=0):
    return 0.05 * np.random.default_rng(seed).standard_normal(n)


def acceleration_box(rig=SMALL, **options):
    return RigGreyBox(
        ["flexural_rigidity", "hub_inertia"],
        rig,
        output="end_acceleration",
        sensors=Sensors.ideal(),
        n_modes=2,
        **options,
    )


def test_modal_state_runs_as_the_rig_from_the_same_state():
    rig = FlexibleManipulator(n_elements=4)
    box = RigGreyBox(["hub_inertia"], rig, sensors=Sensors.ideal())
    x = np.zeros(2 * rig.ndof)
    x[2], x[rig.ndof] = 0.004, 0.3  # a bent beam and a turning hub
    state = box.modal_state(x)
    moving = RigGreyBox(["hub_inertia"], rig, sensors=Sensors.ideal(), x0=state)
    u = torque(300)
    want = rig.simulate(u, fs=1 / TS, sensors=Sensors.ideal(), x0=x).hub_angle
    got = moving.simulate(moving.initial_values, u, TS)
    np.testing.assert_allclose(got, want, rtol=1e-8, atol=1e-12)
    assert np.ptp(got) > 0.1  # the start's motion shows


def test_output_gain_scales_the_output_and_its_matrices():
    u = torque(200)
    plain = acceleration_box()
    scaled = acceleration_box(output_gain=-2.5)
    v = plain.initial_values
    np.testing.assert_allclose(
        scaled.simulate(v, u, TS), -2.5 * plain.simulate(v, u, TS), rtol=1e-12
    )
    free = acceleration_box(output_gain=Parameter(GAIN, -1.0, (-5.0, -0.1)))
    assert free.names[-1] == GAIN
    got = free.simulate(np.r_[v, -2.5], u, TS)
    np.testing.assert_allclose(got, scaled.simulate(v, u, TS), rtol=1e-12)
    c_plain, c_free = plain.matrices(v, TS)[2], free.matrices(np.r_[v, -2.5], TS)[2]
    np.testing.assert_allclose(c_free, -2.5 * c_plain)


def test_start_lands_on_the_truth_frequencies_of_a_simulated_record():
    """A rig no preset: its end acceleration (two modes) fitted by ARX least
    squares; the start from the ARX's modes has the FEM frequencies of the
    truth, found from the preset's far-off start."""
    truth = FlexibleManipulator(
        n_elements=4, youngs_modulus=40e9, hub_inertia=1.5e-3, payload_mass=0.03
    )
    truth_box = acceleration_box(truth)
    u = torque(800)
    y = truth_box.simulate(truth_box.initial_values, u, TS)
    y = y + 1e-3 * np.std(y) * np.random.default_rng(1).standard_normal(y.size)
    data = IOData(u, y, ts=TS)
    arx = identify(data, ARX(4, 5, 0), method="ls")
    box = acceleration_box(FlexibleManipulator(n_elements=4, payload_mass=0.03))
    start = rig_start_from_modes(box, arx, rng=0)
    found = start.rig_at(start.initial_values).modes(2)
    np.testing.assert_allclose(found, truth.modes(2), rtol=0.01)
    preset = box.rig_at(box.initial_values).modes(2)
    assert np.all(np.abs(preset / truth.modes(2) - 1) > 0.1)


def test_start_takes_gain_and_state_by_least_squares():
    truth = dataclasses.replace(SMALL, youngs_modulus=100e9, hub_inertia=1e-3)
    known = acceleration_box(truth)
    state = np.array([0.0, 0.02, -0.01, 0.5, 0.3, 0.1])
    shown = acceleration_box(truth, output_gain=-3.0, x0=state)
    u = torque(500)
    data = IOData(u, shown.simulate(shown.initial_values, u, TS), ts=TS)
    box = acceleration_box(
        output_gain=Parameter(GAIN, 1.0, (0.5, 2.0)),
        x0=[Parameter(f"s{i}", 0.0, (-1.0, 1.0)) for i in range(6)],
    )
    start = rig_start_from_modes(box, truth.modes(2), data, rng=0)
    v = start.initial_values
    np.testing.assert_allclose(v[:2], known.initial_values, rtol=1e-3)
    assert v[2] == pytest.approx(-3.0, rel=1e-3)
    # The rigid mode's position and velocity do not reach the acceleration:
    # only the flexible modes' state is determined.
    np.testing.assert_allclose(v[3:][[1, 2, 4, 5]], state[[1, 2, 4, 5]], rtol=1e-3)
    low, high = start.all_parameters[2].bounds
    assert low < -3.0 < high  # rebuilt around the value, sign and all
    fit = 100 * (
        1 - np.linalg.norm(start.simulate(v, u, TS) - data.y) / np.linalg.norm(data.y)
    )
    assert fit > 99.9


def test_gain_and_state_read_back(tmp_path):
    box = acceleration_box(
        output_gain=Parameter(GAIN, -1.0, (-4.0, -0.25)),
        x0=[0.0, Parameter("s1", 0.01, (-1.0, 1.0)), 0.0, 0.0, 0.2, 0.0],
    )
    back = RigGreyBox.from_dict(json.loads(json.dumps(box.to_dict())))
    assert back.names == box.names
    u = torque(100)
    v = box.initial_values
    np.testing.assert_array_equal(back.simulate(v, u, TS), box.simulate(v, u, TS))


@pytest.mark.parametrize(
    "call, error, words",
    [
        (lambda: acceleration_box(output_gain=0.0), ValueError, "output_gain"),
        (lambda: acceleration_box(output_gain="2"), TypeError, "output_gain"),
        (
            lambda: acceleration_box(output_gain=Parameter("k", 1.0, (0.5, 2.0))),
            ValueError,
            "output_gain",
        ),
        (
            lambda: RigGreyBox(
                ["hub_inertia"],
                FlexibleManipulator(coulomb_friction=0.01),
                x0=[1.0] * 42,
            ),
            ValueError,
            "x0",
        ),
        (lambda: rig_start_from_modes("box", [10.0]), TypeError, "box"),
        (lambda: rig_start_from_modes(acceleration_box(), []), ValueError, "modes"),
        (lambda: rig_start_from_modes(acceleration_box(), [-1.0]), ValueError, "modes"),
        (
            lambda: rig_start_from_modes(acceleration_box(), [5.0, 9.0, 20.0]),
            ValueError,
            "modes",
        ),
        # Two modes a factor 1.1 apart: no uniform beam on a hub has them.
        (
            lambda: rig_start_from_modes(acceleration_box(), [10.0, 11.0]),
            ValueError,
            "no rig",
        ),
        (
            lambda: rig_start_from_modes(acceleration_box(), [10.0], starts=-1),
            ValueError,
            "starts",
        ),
        (
            lambda: rig_start_from_modes(
                RigGreyBox(
                    ["hub_inertia"], SMALL, output=("hub_angle", "end_acceleration")
                ),
                [10.0],
                sid.sysid.IOData(np.zeros(50), np.zeros((50, 2)), ts=0.002),
            ),
            ValueError,
            "one sensor",
        ),
    ],
)
def test_bad_input_is_one_line(call, error, words):
    with pytest.raises(error, match=words) as info:
        call()
    assert "\n" not in str(info.value)


def test_package_names_the_start():
    assert sid.fms.rig_start_from_modes is rig_start_from_modes
