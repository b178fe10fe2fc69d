"""Sampled simulation of the rig against independent computations."""

import numpy as np
import pytest
from scipy import signal
from scipy.signal import find_peaks

import spiralid
from spiralid.fms import FlexibleManipulator, Sensors, bang_bang, paper_experiment

L, WIDTH, THICK, RHO, IH = 0.9, 19.008e-3, 3.2004e-3, 2710.0, 5.86e-4
RHO_A = RHO * WIDTH * THICK


def _physical_ss(rig):
    """Continuous model in physical coordinates, built from M, K, C directly.

    Outputs: hub angle, hub velocity, end acceleration L theta'' + w_L'',
    tip deflection.
    """
    M, K, C = rig.mass_matrix, rig.stiffness_matrix, rig.damping_matrix
    n = rig.ndof
    Mi = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ K, -Mi @ C]])
    e = np.zeros(n)
    e[0] = 1.0
    B = np.concatenate([np.zeros(n), Mi @ e])
    c = np.zeros(n)
    c[0], c[n - 2] = rig.length, 1.0
    eye = np.eye(2 * n)
    Cout = np.vstack(
        [eye[0], eye[n], np.concatenate([-c @ Mi @ K, -c @ Mi @ C]), eye[n - 2]]
    )
    Dout = np.array([0.0, 0.0, c @ Mi @ e, 0.0])
    return A, B, Cout, Dout


def _dlsim(rig, u, fs, x0=None):
    A, B, C, D = _physical_ss(rig)
    sysd = signal.cont2discrete((A, B[:, None], C, D[:, None]), 1 / fs, "zoh")
    _, y, x = signal.dlsim(sysd, u, x0=x0)
    return y, x


def _rel_err(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        {"payload_mass": 0.05, "payload_inertia": 1e-4, "hub_friction": 0.02},
        {"damping_ratio": 0.0, "n_elements": 3},
    ],
)
def test_matches_scipy_zoh_of_the_physical_model(kwargs):
    rig = FlexibleManipulator(**kwargs)
    rng = np.random.default_rng(5)
    u = rng.normal(size=700)
    x0 = np.concatenate([rng.normal(size=rig.ndof) * 1e-3, rng.normal(size=rig.ndof)])
    rec = rig.simulate(u, fs=500.0, sensors=Sensors.ideal(), x0=x0, return_state=True)
    y, x = _dlsim(rig, u, 500.0, x0=x0)
    for k, name in enumerate(
        ("hub_angle", "hub_velocity", "end_acceleration", "tip_deflection")
    ):
        assert _rel_err(getattr(rec, name), y[:, k]) < 1e-8, name
    assert _rel_err(rec.state, x) < 1e-8


@pytest.mark.parametrize("n_samples", [1, 5, 16, 17, 257])
def test_block_simulation_matches_scipy_for_any_record_length(n_samples):
    # The lifted simulation works in blocks of max(16, sqrt(N)) samples (at
    # most 256): lengths below, at and just past a block edge, and one sample.
    rig = FlexibleManipulator(n_elements=3)
    rng = np.random.default_rng(n_samples)
    u = rng.normal(size=n_samples)
    x0 = rng.normal(size=2 * rig.ndof) * 1e-2
    rec = rig.simulate(u, sensors=Sensors.ideal(), x0=x0, return_state=True)
    y, x = _dlsim(rig, u, 500.0, x0=x0)
    y, x = y.reshape(n_samples, -1), x.reshape(n_samples, -1)
    assert _rel_err(rec.end_acceleration, y[:, 2]) < 1e-10
    assert _rel_err(rec.state, x) < 1e-10


def test_antialias_filter_matches_scipy_butterworth_in_series():
    rig = FlexibleManipulator(n_elements=4)
    fs = 500.0
    u = bang_bang(0.2, 0.03, 0.01, 0.8, fs)
    sens = Sensors(encoder_lines=None, antialias_order=3, antialias_cutoff=0.6)
    rec = rig.simulate(u, fs=fs, sensors=sens)
    A, B, C, D = _physical_ss(rig)
    z, p, k = signal.butter(3, 2 * np.pi * 0.6 * fs / 2, analog=True, output="zpk")
    # Filter states scaled by wc per state to keep the exponential accurate.
    af, bf, cf, _ = signal.zpk2ss(z, p, k)
    t = np.diag(np.abs(p[0]) ** np.arange(3.0))
    af, bf, cf = np.linalg.solve(t, af @ t), np.linalg.solve(t, bf), cf @ t
    for row, name in ((1, "hub_velocity"), (2, "end_acceleration")):
        n = A.shape[0]
        big = np.block([[A, np.zeros((n, 3))], [bf @ C[row : row + 1], af]])
        bb = np.concatenate([B, bf[:, 0] * D[row]])
        cc = np.concatenate([np.zeros(n), cf[0]])
        sysd = signal.cont2discrete((big, bb[:, None], cc[None], [[0.0]]), 1 / fs)
        _, y, _ = signal.dlsim(sysd, u)
        assert _rel_err(getattr(rec, name), y[:, 0]) < 1e-7, name
    # The encoder channel is not filtered.
    y, _ = _dlsim(rig, u, fs)
    assert _rel_err(rec.hub_angle, y[:, 0]) < 1e-8


def test_acceleration_sample_includes_the_current_torque_feedthrough():
    # From rest, a(0) = D u[0] with D = c^T M^-1 e_theta: the sample is taken
    # on the right-hand side of the hold step.
    rig = FlexibleManipulator()
    rec = rig.simulate(np.ones(3), sensors=Sensors.ideal())
    Mi = np.linalg.inv(rig.mass_matrix)
    expected = rig.length * Mi[0, 0] + Mi[rig.ndof - 2, 0]
    # D is the small remainder of cancelling terms of size L / J: compare on
    # that scale.
    assert rec.end_acceleration[0] == pytest.approx(
        expected, abs=1e-10 * rig.length * Mi[0, 0]
    )
    assert 0 < expected < 1e-4 * rig.length * Mi[0, 0]
    assert rec.hub_angle[0] == 0.0 and rec.hub_velocity[0] == 0.0


@pytest.mark.parametrize("mp", [0.0, 0.05])
def test_bang_bang_leaves_hub_at_rest_at_tau_t2_over_j(mp):
    tau, T = 0.3, 0.1
    rig = FlexibleManipulator(payload_mass=mp)
    u = bang_bang(tau, T, 0.0, 10.0, 500.0)
    rec = rig.simulate(u, sensors=Sensors.ideal())
    J = IH + RHO_A * L**3 / 3 + mp * L**2
    final = rec.hub_angle[-500:]
    assert np.all(np.abs(final / (tau * T**2 / J) - 1) < 0.02)
    assert np.max(np.abs(rec.hub_velocity[-500:])) < 1e-3 * tau * T / J


def test_undamped_unforced_model_conserves_energy():
    rig = FlexibleManipulator(damping_ratio=0.0)
    M, K = rig.mass_matrix, rig.stiffness_matrix
    n = rig.ndof
    rng = np.random.default_rng(3)
    q0 = np.zeros(n)
    q0[1::2] = 0.01 * (np.arange(1, n // 2 + 1) / (n // 2)) ** 2  # bent beam
    qd0 = np.concatenate([[0.5], rng.normal(scale=0.05, size=n - 1)])
    rec = rig.simulate(
        np.zeros(5000),
        fs=500.0,
        sensors=Sensors.ideal(),
        x0=np.concatenate([q0, qd0]),
        return_state=True,
    )
    q, qd = rec.state[:, :n], rec.state[:, n:]
    energy = 0.5 * np.einsum("ki,ij,kj->k", qd, M, qd) + 0.5 * np.einsum(
        "ki,ij,kj->k", q, K, q
    )
    assert np.max(np.abs(energy / energy[0] - 1)) < 1e-6
    # And it is not trivially constant: the strain energy moves.
    strain = 0.5 * np.einsum("ki,ij,kj->k", q, K, q)
    assert np.ptp(strain) > 0.1 * strain[0]


def test_modal_damping_leaves_rigid_mode_undamped():
    # No torque, no friction: angular momentum e_theta^T M q' is conserved,
    # so the hub ends at p / J while the flexible vibration dies out.
    rig = FlexibleManipulator(damping_ratio=0.05)
    n = rig.ndof
    qd0 = np.zeros(n)
    qd0[0] = 1.0
    qd0[1::2] = 0.2
    rec = rig.simulate(
        np.zeros(2500), sensors=Sensors.ideal(), x0=np.concatenate([np.zeros(n), qd0])
    )
    p = rig.mass_matrix[0] @ qd0
    assert rec.hub_velocity[-1] == pytest.approx(p / rig.total_inertia, rel=1e-6)
    # With hub friction c the hub slows as exp(lam t) once the flexible
    # vibration has gone: lam the real non-zero eigenvalue of the physical
    # model, close to -c / J (the hub angle's share in the flexible modes
    # shifts it by about 0.3 %).
    c = 0.05
    rig = FlexibleManipulator(damping_ratio=0.05, hub_friction=c)
    rec = rig.simulate(
        np.zeros(2500), sensors=Sensors.ideal(), x0=np.concatenate([np.zeros(n), qd0])
    )
    ratio = rec.hub_velocity[2000] / rec.hub_velocity[1500]
    ev = np.linalg.eigvals(_physical_ss(rig)[0])
    lam = ev[(np.abs(ev.imag) < 1e-9) & (ev.real < -1e-9)].real.max()
    assert lam == pytest.approx(-c / rig.total_inertia, rel=0.01)
    assert ratio == pytest.approx(np.exp(lam * 1.0), rel=1e-5)


@pytest.mark.parametrize("sensors", [Sensors.ideal(), Sensors()])
def test_end_acceleration_spectrum_peaks_at_the_first_three_modes(sensors):
    fs, n = 500.0, 2048
    rig = FlexibleManipulator()
    u = bang_bang(0.3, 0.04, 0.0, n / fs, fs)
    a = rig.simulate(u, fs=fs, sensors=sensors).end_acceleration
    spec = np.abs(np.fft.rfft(a))
    freqs = np.fft.rfftfreq(n, 1 / fs)
    df = freqs[1]
    peaks, _ = find_peaks(spec)
    top3 = np.sort(freqs[peaks[np.argsort(spec[peaks])[-3:]]])
    np.testing.assert_allclose(top3, rig.modes(3), atol=df)


def test_same_seed_same_noise_and_zero_noise_is_noise_free():
    rig = FlexibleManipulator(n_elements=5)
    u = bang_bang(0.3, 0.05, 0.0, 1.0, 500.0)
    noisy = Sensors(tach_noise=0.1, accel_noise=2.0)
    r1 = rig.simulate(u, rng=42, sensors=noisy)
    r2 = rig.simulate(u, rng=np.random.default_rng(42), sensors=noisy)
    r3 = rig.simulate(u, rng=43, sensors=noisy)
    clean = rig.simulate(u, rng=42, sensors=Sensors())
    assert np.array_equal(r1.end_acceleration, r2.end_acceleration)
    assert np.array_equal(r1.hub_velocity, r2.hub_velocity)
    assert not np.array_equal(r1.end_acceleration, r3.end_acceleration)
    # Zero noise: identical to any other seed and to no seed at all.
    zero = Sensors(tach_noise=0.0, accel_noise=0.0)
    for seed in (None, 1, 2):
        r = rig.simulate(u, rng=seed, sensors=zero)
        assert np.array_equal(r.end_acceleration, clean.end_acceleration)
        assert np.array_equal(r.hub_velocity, clean.hub_velocity)
    # Noise is additive, white, with the requested standard deviations.
    e = r1.end_acceleration - clean.end_acceleration
    v = r1.hub_velocity - clean.hub_velocity
    assert e.std() == pytest.approx(2.0, rel=0.1)
    assert v.std() == pytest.approx(0.1, rel=0.1)
    assert abs(np.corrcoef(e[:-1], e[1:])[0, 1]) < 0.15
    assert np.array_equal(r1.hub_angle, clean.hub_angle)


def test_encoder_quantises_the_hub_angle():
    rig = FlexibleManipulator(n_elements=5)
    u = bang_bang(0.3, 0.1, 0.0, 2.0, 500.0)
    exact = rig.simulate(u, sensors=Sensors.ideal()).hub_angle
    for quad in (1, 4):
        sens = Sensors(encoder_lines=2048, quadrature=quad, antialias_order=0)
        got = rig.simulate(u, sensors=sens).hub_angle
        res = 2 * np.pi / (2048 * quad)
        counts = got / res
        np.testing.assert_allclose(counts, np.round(counts), atol=1e-9)
        assert np.max(np.abs(got - exact)) <= res / 2 + 1e-15
        assert np.unique(got).size > 5


def test_iodata_wraps_the_chosen_channel():
    pytest.importorskip("spiralid.sysid.data")
    rec = FlexibleManipulator(n_elements=4).simulate(np.ones(10), fs=100.0)
    d = rec.iodata("hub_velocity")
    assert isinstance(d, spiralid.IOData)
    np.testing.assert_array_equal(d.y, rec.hub_velocity)
    np.testing.assert_array_equal(d.u, rec.u)
    assert d.ts == pytest.approx(0.01) and d.output_name == "hub_velocity"
    with pytest.raises(ValueError, match="`name` must be one of"):
        rec.iodata("tip_velocity")
    with pytest.raises(TypeError, match="`name` must be one of"):
        rec.iodata(np.array(["hub_angle", "u"]))


def test_recording_time_axis_and_top_level_exports():
    rec = spiralid.FlexibleManipulator(n_elements=3).simulate([0.0, 1.0, 0.0], fs=4.0)
    np.testing.assert_allclose(rec.t, [0.0, 0.25, 0.5])
    assert rec.ts == 0.25 and isinstance(rec, spiralid.Recording)
    assert spiralid.fms.FlexibleManipulator is spiralid.FlexibleManipulator


def test_paper_experiment_returns_hub_and_shows_three_modes():
    exp = paper_experiment()
    rec = exp.run(rng=0)
    assert rec.u.size == 3000 and rec.ts == pytest.approx(0.002)
    rig = FlexibleManipulator()
    # Alternating pulses: the rigid hub ends where it started.
    rigid = np.cumsum(np.cumsum(rec.u)) * rec.ts**2 / rig.total_inertia
    assert abs(rigid[-1]) < 1e-12
    assert np.max(np.abs(rec.hub_angle)) < 0.2
    f, p = signal.welch(rec.end_acceleration, fs=500.0, nperseg=512)
    peaks, _ = find_peaks(p)
    top3 = np.sort(f[peaks[np.argsort(p[peaks])[-3:]]])
    np.testing.assert_allclose(top3, rig.modes(3), atol=f[1])
    # Validation third still excited.
    a = rec.end_acceleration
    assert a[2000:].std() > 0.3 * a[:2000].std()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"length": 0.0}, "`length` must be a finite number > 0"),
        ({"width": -1.0}, "`width` must be"),
        ({"thickness": np.nan}, "`thickness` must be"),
        ({"youngs_modulus": 0}, "`youngs_modulus` must be"),
        ({"density": -2710.0}, "`density` must be"),
        ({"hub_inertia": 0.0}, "`hub_inertia` must be"),
        ({"payload_mass": -0.1}, "`payload_mass` must be a finite number >= 0"),
        ({"hub_friction": np.inf}, "`hub_friction` must be"),
        ({"damping_ratio": 1.0}, r"`damping_ratio` must be in \[0, 1\)"),
        ({"n_elements": 0}, "`n_elements` must be an integer >= 1; got 0"),
        ({"n_elements": 2.5}, "`n_elements` must be an integer >= 1"),
        # Wrong types used to escape as TypeErrors from float().
        ({"length": "a"}, r"^`length` must be a finite number > 0; got 'a'"),
        ({"length": None}, r"^`length` must be a finite number > 0; got None"),
        ({"width": [0.02]}, r"^`width` must be a finite number > 0; got \[0\.02\]"),
        ({"thickness": 1j}, r"^`thickness` must be a finite number > 0; got 1j"),
        ({"payload_mass": "x"}, r"^`payload_mass` must be a finite number >= 0"),
        ({"damping_ratio": None}, r"^`damping_ratio` must be in \[0, 1\); got None"),
        ({"damping_ratio": -0.1}, r"^`damping_ratio` must be in \[0, 1\)"),
    ],
)
def test_bad_rig_parameters_raise(kwargs, match):
    with pytest.raises((TypeError, ValueError), match=match):
        FlexibleManipulator(**kwargs)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (
            lambda r: r.simulate([0.0, np.nan]),
            r"`torque` must be finite; got nan at index 1",
        ),
        (lambda r: r.simulate([np.inf]), "`torque` must be finite"),
        (lambda r: r.simulate([]), "`torque` must be a non-empty 1-D"),
        (lambda r: r.simulate(np.ones((3, 2))), r"got shape \(3, 2\)"),
        (lambda r: r.simulate([1.0], fs=0.0), "`fs` must be a finite number > 0"),
        (lambda r: r.simulate([1.0], fs=-500.0), "`fs` must be"),
        (lambda r: r.simulate([1.0], fs=np.nan), "`fs` must be"),
        (lambda r: r.simulate([1.0], x0=[1.0, 2.0]), "`x0` must hold 10 finite"),
        (lambda r: r.simulate([1.0], sensors="ideal"), "`sensors` must be a Sensors"),
        (lambda r: r.modes(0), "`n` must be an integer >= 1"),
        (lambda r: r.modes(5), r"^`n` must be at most 2 n_elements = 4 .*got 5"),
        (lambda r: r.simulate("abc"), r"^`torque` must be an array of real numbers"),
        (lambda r: r.simulate([[1], [2, 3]]), r"^`torque` must be an array of real"),
        (lambda r: r.simulate(np.ones(3) + 1j), r"^`torque` must be an array of real"),
        (lambda r: r.simulate([1.0], fs="abc"), r"^`fs` must be a finite number > 0"),
        (lambda r: r.simulate([1.0], fs="500"), r"^`fs` must be a finite number > 0"),
        (lambda r: r.simulate([1.0], rng="a"), r"^`rng` must be None, a non-negative"),
        (lambda r: r.simulate([1.0], rng=1.5), r"^`rng` must be None, a non-negative"),
        (
            lambda r: r.simulate([1.0], x0=np.zeros((2, 5))),
            r"^`x0` must hold 10 finite numbers \(q, q'\), shape \(10,\)",
        ),
        (lambda r: r.simulate([1.0], x0="abcdefghij"), r"^`x0` must be an array"),
        (
            lambda r: r.simulate([1.0], return_state="no"),
            r"^`return_state` must be True or False; got 'no'",
        ),
        (
            lambda r: r.simulate([1.0, 1.0, 1.0], fs=1e-300),
            r"^`torque` and `fs` drive the model beyond the float range",
        ),
    ],
)
def test_bad_simulate_arguments_raise(call, match):
    with pytest.raises((TypeError, ValueError), match=match):
        call(FlexibleManipulator(n_elements=2))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"encoder_lines": 0}, "`encoder_lines` must be an integer >= 1"),
        ({"quadrature": 0}, "`quadrature` must be an integer >= 1"),
        ({"tach_noise": -1.0}, "`tach_noise` must be a finite number >= 0"),
        ({"accel_noise": np.nan}, "`accel_noise` must be"),
        ({"antialias_order": -1}, r"`antialias_order` must be an integer in \[0, 12\]"),
        ({"antialias_cutoff": 1.5}, r"`antialias_cutoff` must be in \(0, 1\]"),
        ({"antialias_cutoff": None}, r"^`antialias_cutoff` must be in \(0, 1\]"),
        ({"antialias_cutoff": "a"}, r"^`antialias_cutoff` must be in \(0, 1\]"),
        ({"tach_noise": None}, r"^`tach_noise` must be a finite number >= 0"),
        ({"accel_noise": "a"}, r"^`accel_noise` must be a finite number >= 0"),
        ({"encoder_lines": 2048.0}, r"^`encoder_lines` must be an integer >= 1"),
        ({"antialias_order": 2.0}, r"^`antialias_order` must be an integer"),
    ],
)
def test_bad_sensor_parameters_raise(kwargs, match):
    with pytest.raises((TypeError, ValueError), match=match):
        Sensors(**kwargs)
