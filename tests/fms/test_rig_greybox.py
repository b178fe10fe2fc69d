"""The rig as a grey box against the simulator that made its records: a
rig variant that is no preset (another payload and hub, other friction),
recorded without noise by ``FlexibleManipulator.simulate``, gives back its
parameters; the fitted modes are the finite-element model's; unknown fields
and clashing ones are refused in one line; model.json reads back; the
command line fits and writes it."""

import json

import numpy as np
import pytest
from clitools import run

import spiralid as sid
from spiralid.choices import RIG_PARAMETERS
from spiralid.fms import FlexibleManipulator, Sensors, bang_bang
from spiralid.fms.greybox import RigGreyBox

# A small rig (4 elements) keeps the full model's runs quick.
VARIANT = dict(
    n_elements=4,
    payload_mass=0.04,
    hub_inertia=7.5e-4,
    damping_ratio=0.03,
)
FS = 500.0


def torque(duration=2.0):
    u = np.zeros(int(duration * FS))
    for j, start in enumerate((0.05, 0.6, 1.2)):
        u += (-1) ** j * bang_bang(0.3, 0.04, start, duration, FS)
    return u


def record(rig, output="hub_angle", sensors=None, duration=2.0):
    sensors = Sensors.ideal() if sensors is None else sensors
    return rig.simulate(torque(duration), fs=FS, sensors=sensors).iodata(output)


def test_the_grey_box_runs_the_simulator_and_its_filter():
    rig = FlexibleManipulator(**VARIANT)
    sensors = Sensors(encoder_lines=None)  # the anti-aliasing filter on
    rec = record(rig, "end_acceleration", sensors)
    box = RigGreyBox(["payload_mass"], rig, output="end_acceleration")
    np.testing.assert_array_equal(
        box.simulate(box.initial_values, rec.u, rec.ts), rec.y
    )


def test_a_linear_variant_gives_back_its_parameters():
    truth = FlexibleManipulator(**VARIANT)
    rec = record(truth, "end_acceleration")
    start = FlexibleManipulator(n_elements=4, payload_mass=0.025, hub_inertia=6e-4)
    box = RigGreyBox(
        ["payload_mass", "hub_inertia", "damping_ratio"], start,
        output="end_acceleration", sensors=Sensors.ideal(),
    )  # fmt: skip
    model = sid.identify(rec, box, method="oe")
    assert model.is_linear
    np.testing.assert_allclose(model.values, [0.04, 7.5e-4, 0.03], rtol=1e-5)
    # The fitted model's poles are the finite elements' modes (an
    # eigenproblem of the mass and stiffness, apart from the sampling).
    s = np.log(model.poles.astype(complex)) * FS
    hz = np.abs(s[s.imag > 0]) / (2 * np.pi)
    for f in truth.modes(3):
        assert np.min(np.abs(hz / f - 1)) < 1e-6, (f, hz)
    assert "fitted Hz" in box.modes_beside(model.values)


def test_a_friction_variant_gives_back_its_friction_within_its_intervals():
    truth = FlexibleManipulator(
        **VARIANT, coulomb_friction=0.015, static_friction=0.025, friction_substeps=5
    )
    rec = record(truth, "hub_angle")
    start = FlexibleManipulator(
        **VARIANT, coulomb_friction=0.012, static_friction=0.03, friction_substeps=5
    )
    box = RigGreyBox(["coulomb_friction", "static_friction"], start)
    assert box.kind == "nonlinear"
    model = sid.identify(rec, box, method="oe", polish_nfev=60)
    assert type(model) is sid.sysid.GreyBoxModel
    np.testing.assert_allclose(model.values, [0.015, 0.025], rtol=1e-3)
    low, high = model.intervals.T
    assert np.all(low <= model.values) and np.all(model.values <= high)


def test_the_reduced_model_keeps_the_first_modes():
    rig = FlexibleManipulator(**VARIANT)
    box = RigGreyBox(["hub_inertia"], rig, output="end_acceleration", n_modes=2)
    # rigid + 2 modes, and the 4th-order filters of the tachometer and the
    # accelerometer (the rig's model filters both)
    assert box.n_states == 2 * 3 + 2 * 4
    a = box.matrices(box.initial_values, 1 / FS)[0][:6, :6]
    eig = np.linalg.eigvals(a)
    hz = np.sort(np.abs(eig[eig.imag > 0])) / (2 * np.pi)
    np.testing.assert_allclose(hz, rig.modes(2), rtol=1e-9)


def test_bad_fields_are_refused_in_one_line():
    with pytest.raises(
        ValueError, match=r"`free` must be one of \('length'.*got 'stiffness'"
    ):
        RigGreyBox(["stiffness"])
    with pytest.raises(ValueError, match="flexural_rigidity is computed from"):
        RigGreyBox(["flexural_rigidity", "youngs_modulus"])
    with pytest.raises(ValueError, match="torque_limit is None"):
        RigGreyBox(["torque_limit"])
    with pytest.raises(ValueError, match="`n_modes` must be at most"):
        RigGreyBox(["hub_inertia"], FlexibleManipulator(n_elements=2), n_modes=5)
    with pytest.raises(TypeError, match="`free` must be"):
        RigGreyBox("hub_inertia")
    assert set(RIG_PARAMETERS) >= {"flexural_rigidity", "static_friction"}


def test_default_bounds_are_a_factor_around_the_preset():
    rig = FlexibleManipulator()
    box = RigGreyBox(["flexural_rigidity", "payload_mass", "damping_ratio"], rig)
    ei, payload, zeta = box.parameters
    assert ei.log and ei.value == pytest.approx(rig.flexural_rigidity)
    assert ei.bounds == pytest.approx(
        (rig.flexural_rigidity / 4, rig.flexural_rigidity * 4)
    )
    assert not payload.log and payload.bounds[0] == 0.0 and payload.unit == "kg"
    assert zeta.bounds[1] < 1.0
    # flexural_rigidity and mass_per_length set E and rho: the rig's own
    # properties read them back.
    box = RigGreyBox([*box.names, "mass_per_length"], rig)
    assert box.initial_values[-1] == pytest.approx(rig.density * rig.area)
    moved = box.rig_at([2.0, 0.01, 0.05, 0.1])
    assert moved.flexural_rigidity == pytest.approx(2.0)
    assert moved.density * moved.area == pytest.approx(0.1)
    assert moved.payload_mass == 0.01 and moved.damping_ratio == 0.05


def test_model_json_round_trip(tmp_path):
    truth = FlexibleManipulator(**VARIANT)
    rec = record(truth, "hub_angle", duration=1.5)
    box = RigGreyBox(["hub_inertia"], FlexibleManipulator(n_elements=4), n_modes=3)
    model = sid.identify(rec, box, method="oe", polish_nfev=20)
    path = tmp_path / "model.json"
    path.write_text(json.dumps(model.to_dict()))
    back = sid.sysid.load_model(path)
    assert type(back.structure) is RigGreyBox and back.structure.n_modes == 3
    np.testing.assert_array_equal(back.simulate(rec), model.simulate(rec))
    np.testing.assert_array_equal(back.intervals, model.intervals)
    assert back.summary() == model.summary()


def test_the_command_line_fits_the_rig(tmp_path):
    truth = FlexibleManipulator(**VARIANT)
    rec = record(truth, "hub_angle", duration=1.5)
    np.savez(tmp_path / "rec.npz", u=rec.u, y=rec.y, ts=rec.ts)
    out = run(
        "identify", "rec.npz", "--model", "rig", "--free", "hub_inertia,payload_mass",
        "--sensor", "hub_angle", "--modes", "4", "--method", "oe", "--out", "fit",
        "--quiet", cwd=tmp_path,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    summary = (tmp_path / "fit" / "summary.txt").read_text()
    assert "hub_inertia" in summary and "FEM preset Hz" in summary
    model = sid.sysid.load_model(tmp_path / "fit" / "model.json")
    assert model.structure.names == ("hub_inertia", "payload_mass")
    out = run(
        "identify", "rec.npz", "--model", "rig", "--free", "stiffness",
        "--out", "bad", cwd=tmp_path,
    )  # fmt: skip
    assert out.returncode == 2 and "unknown field stiffness" in out.stderr
    assert not (tmp_path / "bad").exists()


def test_a_point_outside_the_box_runs_at_its_projection():
    # The paper's searches, as printed, may step outside the unit box: the
    # rig is then run at the nearest point inside, never at a length of
    # kilometres.
    from spiralid.sysid.estimation.greybox.problem import GreyBoxProblem

    rig = FlexibleManipulator(n_elements=4)
    rec = record(rig, "hub_angle")
    box = RigGreyBox(["length", "hub_inertia"], rig)
    problem = GreyBoxProblem(rec, box)
    values = problem.values([7.0, -3.0])
    assert values[0] == pytest.approx(box.parameters[0].bounds[1])
    assert values[1] == pytest.approx(box.parameters[1].bounds[0])
    assert problem([7.0, -3.0]) == problem([1.0, 0.0])


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--method", "ls"], "--method ls does not fit --model rig: spiral, oe"),
        (["--method", "oe", "--points", "7"], "--points does not apply to --method oe"),
        (["--na", "4"], "--na applies to --model arx, narx and polynomial"),
    ],
)
def test_the_command_refuses_what_the_rig_cannot_take(extra, message):
    from spiralid.cli import build_parser
    from spiralid.cli.errors import UsageError
    from spiralid.cli.identify import _check_options

    argv = ["identify", "r.csv", "--model", "rig", "--free", "hub_inertia", *extra]
    with pytest.raises(UsageError, match=message):
        _check_options(build_parser().parse_args(argv))


def test_the_command_says_where_the_sensor_came_from():
    from argparse import Namespace

    from spiralid.cli.errors import UsageError
    from spiralid.cli.rig import _structure

    args = Namespace(free=["hub_inertia"], rig="default", sensor=None, modes=None)
    data = sid.IOData(np.zeros(10), np.zeros(10), ts=0.01)  # its output is "y"
    with pytest.raises(UsageError, match=r"got 'y' \(the record's output name; set"):
        _structure(args, data)
    args.sensor = "end_acceleration"
    assert _structure(args, data).output == "end_acceleration"
