"""The rig grey box fitted to several sensors at once, against the simulator
that made the record: the two sensors' runs are the simulator's (the
accelerometer's anti-aliasing filter beside the unfiltered encoder); on a
record of the hub angle and the tip accelerometer, each with noise of a
known level added, the two-sensor fit recovers the rig variant's parameters
at least as well as either sensor's alone and estimates the noise levels
added; each output's fit is ``validate``'s; model.json reads back; the
command line takes ``--sensor a,b``; bad sensor lists are refused in one
line."""

import json

import numpy as np
import pytest
from clitools import run

import spiralid as sid
from spiralid.fms import FlexibleManipulator, Sensors, bang_bang
from spiralid.fms.greybox import RigGreyBox

FS = 500.0
VARIANT = dict(n_elements=4, payload_mass=0.04, hub_inertia=7.5e-4, damping_ratio=0.03)
START = FlexibleManipulator(n_elements=4, payload_mass=0.025, hub_inertia=6e-4)
FREE = ["flexural_rigidity", "hub_inertia", "payload_mass", "damping_ratio"]
SENSORS = ("hub_angle", "end_acceleration")
# Noise of each sensor in shares of its standard deviation.
NOISE = np.array([0.05, 0.3])


def torque(duration=2.0):
    u = np.zeros(int(duration * FS))
    for j, start in enumerate((0.05, 0.6, 1.2)):
        u += (-1) ** j * bang_bang(0.3, 0.04, start, duration, FS)
    return u


def truth_values(rig):
    return np.array([rig.flexural_rigidity, 7.5e-4, 0.04, 0.03])


@pytest.fixture(scope="module")
def noisy():
    truth = FlexibleManipulator(**VARIANT)
    rec = truth.simulate(torque(), fs=FS, sensors=Sensors.ideal()).iodata(list(SENSORS))
    sd = NOISE * rec.y.std(axis=0)
    y = rec.y + sd * np.random.default_rng(0).standard_normal(rec.y.shape)
    return sid.IOData(rec.u, y, ts=rec.ts, output_name=SENSORS), sd, truth


@pytest.fixture(scope="module")
def fits(noisy):
    data, _, _ = noisy
    out = {}
    for sensor in (*SENSORS, SENSORS):
        box = RigGreyBox(FREE, START, output=sensor, sensors=Sensors.ideal())
        one = data.select_outputs(list(sensor)) if sensor == SENSORS else None
        out[sensor] = sid.identify(
            one if one is not None else data.output(sensor), box, method="oe"
        )
    return out


def test_two_sensors_run_as_the_simulator_with_its_filters():
    rig = FlexibleManipulator(**VARIANT)
    sensors = Sensors(encoder_lines=None)  # the accelerometer's filter on
    rec = rig.simulate(torque(), fs=FS, sensors=sensors).iodata(list(SENSORS))
    box = RigGreyBox(["payload_mass"], rig, output=SENSORS, sensors=sensors)
    assert box.n_outputs == 2 and box.outputs == SENSORS
    np.testing.assert_array_equal(
        box.simulate(box.initial_values, rec.u, rec.ts), rec.y
    )


def test_two_sensors_recover_the_rig_at_least_as_well_as_either(noisy, fits):
    _, sd, truth = noisy
    errors = {
        k: float(np.linalg.norm(m.values / truth_values(truth) - 1.0))
        for k, m in fits.items()
    }
    both = errors.pop(SENSORS)
    assert both <= min(errors.values()), (both, errors)
    model = fits[SENSORS]
    low, high = model.intervals.T
    assert np.all((low <= truth_values(truth)) & (truth_values(truth) <= high))
    # The noise levels the fit weighs the sensors by are those added.
    np.testing.assert_allclose(1.0 / np.sqrt(model.weights), sd, rtol=0.1)


def test_each_sensors_fit_is_validates(noisy, fits):
    data, _, _ = noisy
    model = fits[SENSORS]
    v = sid.validate(model, data)
    for name in SENSORS:
        assert v.outputs[name].fit_percent == pytest.approx(
            model.output_fits[name], abs=1e-9
        )
    # The single-sensor fits report the same measure.
    assert fits["hub_angle"].output_fits["hub_angle"] == pytest.approx(
        sid.validate(fits["hub_angle"], data.output("hub_angle")).fit_percent,
        abs=1e-9,
    )


def test_the_two_sensor_model_reads_back(noisy, fits, tmp_path):
    data, _, _ = noisy
    model = fits[SENSORS]
    path = tmp_path / "model.json"
    path.write_text(json.dumps(model.to_dict()))
    back = sid.sysid.load_model(path)
    assert back.structure.outputs == SENSORS
    np.testing.assert_array_equal(back.simulate(data), model.simulate(data))
    assert "hub_angle, end_acceleration" in repr(back.structure)


def test_bad_sensor_lists_are_refused_in_one_line(noisy):
    with pytest.raises(ValueError, match="`output` must be one of"):
        RigGreyBox(["hub_inertia"], output=("hub_angle", "strain"))
    with pytest.raises(ValueError, match="each sensor once"):
        RigGreyBox(["hub_inertia"], output=("hub_angle", "hub_angle"))
    with pytest.raises(TypeError, match="`output` must be a sensor's name"):
        RigGreyBox(["hub_inertia"], output=3)
    data, _, _ = noisy
    box = RigGreyBox(["hub_inertia"], START, output=SENSORS, sensors=Sensors.ideal())
    with pytest.raises(ValueError, match=r"`output` \('hub_angle', 'end_acc.*holds 1"):
        sid.identify(data.output("hub_angle"), box, method="oe")


def test_the_command_line_fits_two_sensors(noisy, tmp_path):
    data, _, _ = noisy
    short = data[:600]
    np.savez(tmp_path / "rec.npz", u=short.u, hub=short.y[:, 0], acc=short.y[:, 1])
    common = ["--model", "rig", "--free", "hub_inertia,payload_mass", "--modes",
              "4", "--method", "oe", "--quiet"]  # fmt: skip
    out = run(
        "identify", "rec.npz", "--output", "hub,acc", "--ts", 1 / FS, *common,
        "--sensor", "hub_angle,end_acceleration", "--out", "fit", cwd=tmp_path,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    summary = (tmp_path / "fit" / "summary.txt").read_text()
    assert "output acc: fit" in summary and "joint fit" in summary
    model = sid.sysid.load_model(tmp_path / "fit" / "model.json")
    assert model.output_names == ("hub", "acc")
    assert model.structure.outputs == SENSORS
    out = run(
        "identify", "rec.npz", "--output", "hub", "--ts", 1 / FS, *common,
        "--sensor", "hub_angle,end_acceleration", "--out", "bad", cwd=tmp_path,
    )  # fmt: skip
    assert out.returncode == 2 and "--sensor names 2 sensor(s)" in out.stderr
    assert not (tmp_path / "bad").exists()
