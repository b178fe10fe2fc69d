"""Sensors along the beam (deflection and accelerometers at a position) and
the nodes of the modes, against independent computations."""

from dataclasses import replace

import numpy as np
import pytest
from scipy import signal
from scipy.optimize import brentq

from spiralid.fms import FlexibleManipulator, Sensors, paper_experiment

CHANNELS = ("hub_angle", "hub_velocity", "end_acceleration", "tip_deflection")


def _hermite_row(rig, x):
    """w(x L) from q, written out by hand: the element holding the point and
    its four cubic Hermite functions."""
    n = rig.n_elements
    le = rig.length / n
    e = min(int(x * n), n - 1)
    xi = x * n - e
    shape = [
        1 - 3 * xi**2 + 2 * xi**3,
        le * (xi - 2 * xi**2 + xi**3),
        3 * xi**2 - 2 * xi**3,
        le * (-(xi**2) + xi**3),
    ]
    row = np.zeros(rig.ndof)
    for local, value in enumerate(shape):
        node, slope = divmod(local, 2)
        j = e + node  # node index along the beam, 0 at the hub
        if j > 0:
            row[2 * j - 1 + slope] = value
    return row


def _physical(rig, deflection_at, acceleration_at):
    """Continuous model in physical coordinates from M, K, C: the deflection
    at each position, then the acceleration x theta'' + w''(x) at each."""
    M, K, C = rig.mass_matrix, rig.stiffness_matrix, rig.damping_matrix
    n = rig.ndof
    Mi = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ K, -Mi @ C]])
    B = np.concatenate([np.zeros(n), Mi[:, 0]])
    rows, feed = [], []
    for x in deflection_at:
        rows.append(np.concatenate([_hermite_row(rig, x), np.zeros(n)]))
        feed.append(0.0)
    for x in acceleration_at:
        c = _hermite_row(rig, x)
        c[0] += x * rig.length
        rows.append(np.concatenate([-c @ Mi @ K, -c @ Mi @ C]))
        feed.append(c @ Mi[:, 0])
    return A, B, np.array(rows), np.array(feed)


def test_sensors_along_the_beam_match_scipy_zoh_of_the_physical_model():
    rig = FlexibleManipulator(payload_mass=0.03, hub_friction=0.01)
    u = np.random.default_rng(3).normal(size=600)
    where = dict(deflection_at=(0.3, 0.75), acceleration_at=(0.5, 0.9))
    rec = rig.simulate(u, sensors=Sensors.ideal(**where))
    A, B, C, D = _physical(rig, where["deflection_at"], where["acceleration_at"])
    sysd = signal.cont2discrete((A, B[:, None], C, D[:, None]), 1 / 500.0, "zoh")
    _, y = signal.dlsim(sysd, u)[:2]
    got = np.hstack([rec.deflection, rec.acceleration])
    scale = np.max(np.abs(y), axis=0)
    assert np.all(np.max(np.abs(got - y), axis=0) < 1e-8 * scale)
    assert rec.output_names[4:] == (
        "deflection_0.3",
        "deflection_0.75",
        "acceleration_0.5",
        "acceleration_0.9",
    )


def test_the_four_channels_and_their_noise_are_unchanged_by_sensors_along_the_beam():
    exp = paper_experiment()
    default = exp.run(rng=7)
    assert default.deflection is None and default.acceleration is None
    assert default.output_names == CHANNELS
    more = replace(exp, deflection_at=(1.0, 0.4), acceleration_at=[1.0, 0.6]).run(rng=7)
    for name in CHANNELS:
        ref = getattr(default, name)
        # Only the extra rows of C change the rounding of the block products.
        np.testing.assert_allclose(
            getattr(more, name), ref, rtol=0, atol=1e-12 * np.max(np.abs(ref))
        )
    # A deflection sensor at the tip is the tip deflection; an accelerometer
    # at the end point is the end-point accelerometer up to its own noise.
    np.testing.assert_array_equal(more.deflection[:, 0], more.tip_deflection)
    noise = more.acceleration[:, 0] - more.end_acceleration
    assert abs(np.std(noise) / np.sqrt(2) - exp.accel_noise) < 0.05
    data = more.iodata(["end_acceleration", "acceleration_0.6", "deflection_0.4"])
    assert data.output_units == ("m/s^2", "m/s^2", "m")
    with pytest.raises(ValueError, match="`name` must be one of"):
        default.iodata("deflection_0.4")


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"deflection_at": (0.0,)}, r"`deflection_at` must be a tuple of positions"),
        ({"acceleration_at": (1.2,)}, r"`acceleration_at` must be a tuple"),
        ({"acceleration_at": 0.5}, r"`acceleration_at` must be a tuple"),
        ({"deflection_at": ("a",)}, r"`deflection_at` must be a tuple"),
        ({"deflection_at": (0.5, 0.5)}, r"`deflection_at` must name distinct"),
    ],
)
def test_bad_positions_raise(kwargs, match):
    with pytest.raises((TypeError, ValueError), match=match):
        Sensors(**kwargs)


def _clamped_free(k):
    """Analytic clamped-free beam: mode k's shape in x / L."""
    # Near (k - 1/2) pi, the k-th root of 1 + cos(bL) cosh(bL) = 0.
    mid = (k - 0.5) * np.pi
    bl = brentq(lambda b: 1 + np.cos(b) * np.cosh(b), mid - 1.0, mid + 0.5)
    sigma = (np.cosh(bl) + np.cos(bl)) / (np.sinh(bl) + np.sin(bl))
    return lambda x: (
        np.cosh(bl * x) - np.cos(bl * x) - sigma * (np.sinh(bl * x) - np.sin(bl * x))
    )


def _pinned_free(k):
    """Analytic pinned-free beam: flexible mode k's shape in x / L."""
    bl = brentq(
        lambda b: np.tan(b) - np.tanh(b), k * np.pi + 0.1, (k + 0.5) * np.pi - 1e-9
    )
    return lambda x: np.sin(bl * x) + np.sin(bl) / np.sinh(bl) * np.sinh(bl * x)


def _analytic_nodes(shape):
    x = np.linspace(1e-3, 1.0, 2001)
    v = shape(x)
    return np.array(
        [brentq(shape, x[i], x[i + 1]) for i in np.flatnonzero(v[:-1] * v[1:] < 0)]
    )


@pytest.mark.parametrize("mode", [2, 3])
def test_nodes_are_those_of_the_clamped_free_beam_when_the_hub_is_heavy(mode):
    # A hub 1e5 times the beam's inertia barely turns: the beam is clamped.
    rig = FlexibleManipulator(hub_inertia=1e3, n_elements=20)
    expected = _analytic_nodes(_clamped_free(mode))
    assert expected.size == mode - 1
    np.testing.assert_allclose(rig.mode_nodes(mode), expected, atol=1e-4)


@pytest.mark.parametrize("mode", [1, 2, 3])
def test_nodes_are_those_of_the_pinned_free_beam_when_the_hub_is_light(mode):
    # Without hub inertia the hub is a pin; an accelerometer's frame.
    rig = FlexibleManipulator(hub_inertia=1e-9, n_elements=20)
    expected = _analytic_nodes(_pinned_free(mode))
    assert expected.size == mode
    got = rig.mode_nodes(mode, frame="inertial")
    np.testing.assert_allclose(got, expected, atol=1e-4)


def test_the_rigs_mode_shape_vanishes_at_its_nodes_and_peaks_at_one():
    rig = FlexibleManipulator()
    grid = np.linspace(0, 1, 1001)
    for frame in ("hub", "inertial"):
        for mode in (1, 2, 3):
            shape = rig.mode_shape(mode, grid, frame=frame)
            assert np.max(np.abs(shape)) == pytest.approx(1.0, abs=1e-3)
            nodes = rig.mode_nodes(mode, frame=frame)
            assert nodes.size >= 1
            assert np.all(np.abs(rig.mode_shape(mode, nodes, frame=frame)) < 1e-9)
            # Between nodes the shape keeps its sign: they are all the nodes.
            changes = np.count_nonzero(np.diff(np.sign(shape[1:])) != 0)
            assert changes == nodes.size
    # An accelerometer at mode 2's outer node barely sees mode 2 (hub turning
    # with the beam: between the pinned-free 0.853 and clamped-free 0.783).
    node = rig.mode_nodes(2, frame="inertial")[-1]
    assert 0.78 < node < 0.86
    with pytest.raises(ValueError, match="`frame` must be 'hub' or 'inertial'"):
        rig.mode_nodes(2, frame="absolute")
    with pytest.raises(ValueError, match="`mode` must be at most 2 n_elements"):
        rig.mode_shape(21, [0.5])
    with pytest.raises(ValueError, match="`positions` must be fractions"):
        rig.deflection_rows([1.5])
