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


def _nonlinear_csv(path):
    """A record of a second-order system with a saturating output map: the
    true lags are 2, so one lag leaves a misfit that two remove."""
    rng = np.random.default_rng(7)
    u = rng.uniform(-1.0, 1.0, 900)
    y = np.zeros_like(u)
    for t in range(2, u.size):
        y[t] = 1.2 * y[t - 1] - 0.5 * y[t - 2] + np.tanh(u[t - 1]) + 0.2 * u[t - 2]
    np.savetxt(path, np.c_[u, y], delimiter=",", header="u,y", comments="")
    return IOData(u, y, ts=1.0)


def test_by_fit_chooses_narx_lags_and_hidden_sizes_as_choose_order(tmp_path):
    """`--by-fit` keeps the candidate the library's choose_order picks from
    the same fits, and says which it was and why."""
    from spiralid.sysid import NARX, choose_order, identify

    data = _nonlinear_csv(tmp_path / "nl.csv")
    proc = run(
        "identify", "nl.csv", "--model", "narx", "--lags", "1,2", "--hidden",
        "2,3", "--nk", "1", "--method", "ls", "--by-fit", "0.5", "--ts", "1",
        "--out", "m", cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    est, val = data.split(2 / 3)
    structures = [NARX(n, n, 1, hidden=(h,)) for n in (1, 2) for h in (2, 3)]
    models = [identify(est, st, method="ls", rng=0) for st in structures]
    want = models[choose_order(models, val, warmup=est, tolerance=0.5)]
    assert want.structure.ny == 2, "one lag cannot fit a second-order record"
    saved = NARXModel.from_dict(json.loads((tmp_path / "m" / "model.json").read_text()))
    assert saved.structure == want.structure
    np.testing.assert_allclose(saved.params, want.params, rtol=1e-9, atol=1e-12)
    assert "chosen by validation fit (--by-fit 0.5)" in proc.stdout
    assert f"{want.structure}: {want.params.size} parameters" in proc.stdout


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--model", "narx", "--hidden", "2,4"], "of --hidden need --by-fit"),
        (["--model", "narx", "--lags", "1,2"], "of --lags need --by-fit"),
        (["--by-fit", "1"], "--by-fit and --lags choose among NARX structures"),
        (["--model", "narx", "--lags", "1,2", "--na", "3", "--by-fit", "1"],
         "--lags replaces --na and --nb"),
        (["--model", "narx", "--hidden", "0"], "--hidden: must be integers >= 1"),
    ],
)  # fmt: skip
def test_by_fit_refuses_what_it_cannot_choose_among(tmp_path, argv, message):
    _nonlinear_csv(tmp_path / "nl.csv")
    proc = run("identify", "nl.csv", *argv, "--ts", "1", "--out", "m", cwd=tmp_path)
    assert proc.returncode == 2 and message in proc.stderr, proc.stderr
    assert not (tmp_path / "m").exists()
