"""The reproduction's modes from every sensor: ``reproduce(all_outputs=True)``
identifies the rig's modes from all four sensors of the same run beside the
paper's single-output model."""

import json
import re

import numpy as np
import pytest
from clitools import run
from scipy.signal import lfilter

from spiralid import ARX, IOData
from spiralid.fms import FlexibleManipulator
from spiralid.report.output import _html, results_dict, summary_text
from spiralid.reproduction import Configuration, default_data, reproduce

# One cheap arm: the shared fit is the point here, not the comparison.
SMALL = dict(
    seeds=1,
    max_nfev=200,
    n_points=10,
    configurations=(Configuration("SDA", "sda"),),
    workers=1,
)


@pytest.fixture(scope="module")
def rep():
    return reproduce(all_outputs=True, **SMALL)


def test_every_sensor_gives_the_fem_s_three_modes(rep):
    fem = FlexibleManipulator().modes(3)
    found = rep.shared.model.modes.table.frequency
    assert rep.shared.model.output_names == (
        "hub_angle",
        "hub_velocity",
        "end_acceleration",
        "tip_deflection",
    )
    for f in fem:
        assert np.min(np.abs(found - f)) / f < 0.005, (f, found)
    np.testing.assert_allclose(rep.shared.fem_hz, fem)
    # The comparison's first row is the shared fit, the FEM's modes matched.
    first = rep.modes_comparison()[0]
    assert first["model"] == "every sensor"
    assert max(abs(e) for e in first["error_percent"]) < 0.5
    # The paper's model runs on the same run's acceleration, unchanged.
    np.testing.assert_array_equal(rep.data.y, default_data().y)
    assert rep.arx.na == 8 and set(rep.runs) == {"SDA"}


def test_the_report_and_results_hold_the_modes_table(rep):
    page = _html(rep, {}, None)
    assert "<h2>Modes from every sensor</h2>" in page
    table = rep.shared.model.modes.table
    assert len(table) >= 3
    # Every interval, to the digits that tell its ends apart: the rig's
    # modes are known to 1e-5 Hz, which four digits would print as one.
    section = page.split("<h2>Modes from every sensor</h2>")[1].split("<h2>")[0]
    shown = [
        (float(a), float(b))
        for a, b in re.findall(r"<td>\[([-\d.e+]+), ([-\d.e+]+)\]</td>", section)
    ]
    exact = np.column_stack([table.frequency_interval, table.damping_interval])
    np.testing.assert_allclose(np.reshape(shown, (-1, 4)), exact, rtol=5e-4, atol=5e-5)
    assert all(lo < hi for lo, hi in shown)
    assert "share in tip_deflection (%)" in page and "FEM (rig.modes(3))" in page
    d = json.loads(json.dumps(results_dict(rep)))
    every = d["modes_from_every_sensor"]
    assert every["integrators"] == [2, 1, 0, 0]
    assert len(every["modes"]["modes"]) == len(table)
    assert every["comparison"][0]["model"] == "every sensor"
    assert "Modes from every sensor" in summary_text(rep)


def test_off_by_default_and_bad_values_refused_in_one_line():
    rng = np.random.default_rng(7)
    u = rng.standard_normal(300)
    data = IOData(u, lfilter([0.0, 0.5], [1.0, -0.5], u), ts=0.01)
    with pytest.raises(TypeError) as bad:
        reproduce(all_outputs="yes", **SMALL)
    assert str(bad.value).startswith("`all_outputs` must be True or False")
    assert "\n" not in str(bad.value)
    with pytest.raises(ValueError) as mine:
        reproduce(data, all_outputs=True, **SMALL)
    assert str(mine.value).startswith("`all_outputs` applies to the simulated rig")
    assert "\n" not in str(mine.value)
    # The default passed by value is the default; nothing is added.
    off = reproduce(data, all_outputs=False, arx=ARX(1, 1, 1), **SMALL)
    assert off.shared is None and off.modes_comparison() == []
    assert "modes_from_every_sensor" not in results_dict(off)
    assert "Modes from every sensor" not in _html(off, {}, None)


def test_the_command_refuses_all_outputs_with_data_in_one_line(tmp_path):
    out = run("reproduce", "--all-outputs", "--data", "robot_arm", "--out", "r",
              cwd=tmp_path)  # fmt: skip
    assert out.returncode == 2 and len(out.stderr.splitlines()) == 1
    assert "--all-outputs" in out.stderr and "--data" in out.stderr
    assert not (tmp_path / "r").exists()


def test_a_model_is_not_credited_with_a_neighbour_s_mode():
    from spiralid.study.modes import _nearest

    hz, err = _nearest([10.0, 20.0, 30.0], [10.1, 29.0, 80.0])
    np.testing.assert_allclose(hz, [10.1, np.nan, 29.0])
    np.testing.assert_allclose(err, [1.0, np.nan, -100.0 / 30.0])
    assert np.isnan(_nearest([10.0], [])[0]).all()


def test_the_every_sensor_names_stay_importable_from_the_reproduction():
    import spiralid.reproduction as reproduction
    import spiralid.study.modes as modes

    for name in ("MODE_WINDOW", "RIG_INTEGRATORS", "RIG_OUTPUTS", "SHARED_ARX",
                 "SharedModesFit"):  # fmt: skip
        assert name in reproduction.__all__
        assert getattr(reproduction, name) is getattr(modes, name)
