"""`spiralid simulate --nonlinear`, `identify --model narx`, `validate` of it."""

import json

import numpy as np
import pytest
from clitools import run

from spiralid.fms import Sensors, nonlinear_rig, prbs
from spiralid.sysid import IOData, NARXModel


def test_nonlinear_record_identify_narx_and_validate(tmp_path):
    proc = run(
        "simulate", "--nonlinear", "--signal", "prbs", "--out", "nl.csv", cwd=tmp_path
    )
    assert proc.returncode == 0, proc.stderr
    data = np.loadtxt(tmp_path / "nl.csv", delimiter=",", skiprows=1)
    rec = nonlinear_rig().simulate(
        prbs(0.1, 6.0, 500.0), rng=0, sensors=Sensors(accel_noise=1.0, tach_noise=0.01)
    )
    assert data.shape[0] == rec.u.size
    np.testing.assert_allclose(data[:, 2], rec.hub_angle, atol=1e-9)

    out = "end_acceleration_m_s2"
    proc = run(
        "identify", "nl.csv", "--output", out, "--model", "narx", "--na", "3",
        "--nb", "3", "--nk", "1", "--hidden", "4", "--method", "ls",
        "--out", "m", cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "Billings-Voon" in proc.stdout
    fields = json.loads((tmp_path / "m" / "model.json").read_text())
    model = NARXModel.from_dict(fields)
    saved = json.loads((tmp_path / "m" / "validation.json").read_text())
    proc = run(
        "validate", "m/model.json", "nl.csv", "--output", out,
        "--fraction", "0.6666666666666666", "--out", "v", cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    again = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert again["fit_percent"] == pytest.approx(
        saved["validation"]["fit_percent"], rel=1e-12
    )
    # The library's model from the file predicts what the command scored.
    d = IOData(data[:, 1], data[:, 4], ts=0.002)
    est, val = d.split(2 / 3)
    whole = model.simulate(d.u)[est.n :]
    yv = val.y
    fit = 100 * (1 - np.linalg.norm(yv - whole) / np.linalg.norm(yv - yv.mean()))
    assert fit == pytest.approx(saved["validation"]["fit_percent"], rel=1e-9)


def test_identify_narx_refuses_arx_only_options(tmp_path):
    run("simulate", "--out", "r.csv", cwd=tmp_path)
    proc = run("identify", "r.csv", "--model", "narx", "--method", "de", cwd=tmp_path)
    assert proc.returncode != 0 and "does not train NARX" in proc.stderr
    proc = run(
        "identify", "r.csv", "--model", "polynomial", "--method", "oe", cwd=tmp_path
    )
    assert proc.returncode != 0 and "--method ls" in proc.stderr
