"""The `spiralid` console script, run as a user would (subprocess)."""

import json
import re
from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from clitools import run

from spiralid import IdentifiedModel, IOData
from spiralid.fms import FlexibleManipulator, paper_experiment

# The shipped copy of the DaISy robot arm record (spiralid/datasets/).
ARM = Path(str(resources.files("spiralid.datasets") / "daisy_robot_arm.csv"))


@pytest.fixture(scope="module")
def rig_csv(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("rig")
    proc = run("simulate", "--out", "rig.csv", "--seed", "3", cwd=tmp)
    assert proc.returncode == 0, proc.stderr
    return tmp / "rig.csv"


def test_help_of_every_subcommand(tmp_path):
    for sub in ("simulate", "identify", "validate", "reproduce"):
        proc = run(sub, "--help", cwd=tmp_path)
        assert proc.returncode == 0
        assert f"usage: spiralid {sub}" in proc.stdout


def test_simulate_csv_matches_the_library(rig_csv):
    header = rig_csv.read_text().splitlines()[0].split(",")
    assert header == [
        "time_s",
        "torque_Nm",
        "hub_angle_rad",
        "hub_velocity_rad_s",
        "end_acceleration_m_s2",
    ]
    table = np.loadtxt(rig_csv, delimiter=",", skiprows=1)
    exp = paper_experiment()
    rec = FlexibleManipulator().simulate(
        exp.torque(), fs=exp.fs, rng=3, sensors=exp.sensors()
    )
    assert table.shape == (rec.u.size, 5)
    np.testing.assert_allclose(table[:, 1], rec.u, rtol=1e-9)
    np.testing.assert_allclose(table[:, 4], rec.end_acceleration, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(np.diff(table[:, 0]), 1 / 500, rtol=1e-6)


def test_simulate_npz_loads_as_iodata(tmp_path):
    proc = run(
        "simulate",
        "--signal",
        "prbs",
        "--duration",
        "1",
        "--out",
        "r.npz",
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    data = IOData.from_npz(tmp_path / "r.npz")
    assert data.n == 500 and data.ts == pytest.approx(0.002)
    assert set(np.unique(data.u)) == {-0.1, 0.1}


def test_simulate_refuses_to_overwrite(rig_csv):
    before = rig_csv.read_bytes()
    proc = run("simulate", "--out", rig_csv.name, cwd=rig_csv.parent)
    assert proc.returncode == 2
    assert "--force" in proc.stderr
    assert rig_csv.read_bytes() == before


@pytest.mark.slow
def test_identify_then_validate(rig_csv, tmp_path):
    proc = run(
        "identify", rig_csv, "--budget", "400", "--out", tmp_path / "m", cwd=tmp_path
    )
    assert proc.returncode == 0, proc.stderr
    assert "fit % (simulation, from rest)" in proc.stdout
    model = IdentifiedModel.from_dict(
        json.loads((tmp_path / "m" / "model.json").read_text())
    )
    # The default method is the recommended one, over the modes.
    assert model.method == "spiral" and model.parametrization == "modal"
    assert model.theta.shape == (16,) and model.is_stable
    saved_model = json.loads((tmp_path / "m" / "model.json").read_text())
    # --budget, not the default 500 iterations, stops the search.
    assert 350 < saved_model["result"]["nfev"] <= 400
    assert (tmp_path / "m" / "validation_time.png").stat().st_size > 1000
    assert (tmp_path / "m" / "convergence.png").exists()
    # The saved model reproduces the same validation on the same data.
    saved = json.loads((tmp_path / "m" / "validation.json").read_text())
    proc = run(
        "validate",
        tmp_path / "m" / "model.json",
        rig_csv,
        "--fraction",
        "0.6666666666666666",
        "--out",
        tmp_path / "v",
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    again = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert again["fit_percent"] == pytest.approx(
        saved["validation"]["fit_percent"], rel=1e-9
    )


def test_identify_reads_mat_files(tmp_path):
    from scipy.io import savemat
    from scipy.signal import lfilter

    u = np.random.default_rng(0).standard_normal(400)
    y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    savemat(tmp_path / "rec.mat", {"torque": u, "accel": y, "ts": 0.01})
    proc = run(
        "identify",
        "rec.mat",
        "--input",
        "torque",
        "--output",
        "accel",
        "--na",
        "2",
        "--nb",
        "2",
        "--nk",
        "1",
        "--method",
        "ls",
        "--out",
        "m",
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    model = json.loads((tmp_path / "m" / "model.json").read_text())
    # Noise-free data from a model of the same structure: exact recovery.
    np.testing.assert_allclose(model["theta"], [-1.5, 0.7, 1.0, 0.5], atol=1e-9)


@pytest.mark.slow
def test_validate_refuses_data_at_another_sample_time(rig_csv, tmp_path):
    proc = run("identify", rig_csv, "--method", "ls", "--out", "m", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    fast = tmp_path / "fast.csv"
    proc = run("simulate", "--fs", "1000", "--out", fast, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    proc = run("validate", "m/model.json", fast, cwd=tmp_path)
    assert proc.returncode == 2
    assert "sample time" in proc.stderr


@pytest.mark.slow
def test_reproduce_force_keeps_the_users_files(tmp_path):
    out = tmp_path / "rep"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    (out / "results.json").write_text("stale")
    proc = run(
        "reproduce",
        *("--seeds", "1", "--budget", "100", "--points", "10", "--workers", "1"),
        *("--quiet", "--force", "--out", out),
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    assert (out / "notes.txt").read_text() == "mine"
    assert json.loads((out / "results.json").read_text())["seeds"] == [0]


def test_identify_least_squares_on_the_real_arm(tmp_path):
    # The shipped record by name: its own ts = 0.01 s.
    proc = run("identify", "robot_arm", "--method", "ls", "--out", "arm", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "robot_arm" in (tmp_path / "arm" / "summary.txt").read_text()
    val = json.loads((tmp_path / "arm" / "validation.json").read_text())["validation"]
    # The data's README: least-squares ARX(8, 8, 0) validates at about 95 %.
    assert abs(val["fit_percent"] - 95.0) <= 1.0


@pytest.mark.slow
def test_identify_an_fir_model_with_the_default_method(tmp_path):
    # `--na 0` has no denominator for the modal search: the default method
    # solves the FIR model exactly, as output error does.
    proc = run("identify", "robot_arm", "--na", "0", "--out", "fir", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    model = IdentifiedModel.from_dict(
        json.loads((tmp_path / "fir" / "model.json").read_text())
    )
    assert (model.arx.na, model.method) == (0, "spiral")
    oe = run("identify", "robot_arm", "--na", "0", "--method", "oe", "--out", "oe",
             cwd=tmp_path)  # fmt: skip
    assert oe.returncode == 0, oe.stderr
    oe_model = json.loads((tmp_path / "oe" / "model.json").read_text())
    assert model.cost == pytest.approx(oe_model["cost"], rel=1e-9)


def _reproduce_ok(tmp_path, *extra):
    out = tmp_path / "rep"
    proc = run(
        "reproduce",
        "--seeds",
        "2",
        "--budget",
        "300",
        "--points",
        "10",
        "--workers",
        "1",
        "--quiet",
        "--out",
        out,
        *extra,
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    results = json.loads((out / "results.json").read_text())
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") == 6
    for stem in ("fig6a_convergence", "fig7c_spectrum", "pole_zero"):
        assert (out / f"{stem}.png").stat().st_size > 1000
    return results


@pytest.mark.slow
def test_reproduce_on_the_simulated_rig(tmp_path):
    results = _reproduce_ok(tmp_path)
    assert results["seeds"] == [0, 1]
    assert results["data"]["kind"] == "simulated rig"
    assert results["options"]["initial"] == "rest"
    assert results["data"]["rig"]["length"] == 0.9
    assert results["data"]["n_samples"] == 3000 and results["data"]["ts"] == 0.002
    assert results["structure"] == {"na": 8, "nb": 8, "nk": 0}
    labels = [row["label"] for row in results["table2"]]
    assert labels == [
        "SDA",
        "Eb-SDA",
        "SDA (reflection)",
        "Eb-SDA (reflection)",
        "Eb-SDA + refine",
        "Eb-SDA (w x 0.1)",
        "Eb-SDA (w x 10)",
        "DE",
        "DE (reflection)",
        "spiral (recommended)",
        "LS",
        "OE",
    ]
    for runs in results["runs"].values():
        assert [r["seed"] for r in runs] == [0, 1]
        assert all(r["nfev"] <= 300 for r in runs)
        assert all(len(r["history"]) == r["nit"] + 1 for r in runs)
    # The gain-scaled arms search at w x 10 but are scored at the default w.
    w = results["options"]["gain"]
    for arm in results["runs"]["Eb-SDA (w x 10)"]:
        assert arm["gain"] == pytest.approx(10 * w)
        assert arm["search_cost"] == pytest.approx(10 * arm["cost_estimation"])
    assert results["rules"]["ebsda"]["r_c1"] == 100.0
    assert results["rules"]["sda"]["radius"] == 0.95
    stats = results["statistics"]["SDA"]
    costs = [r["cost_estimation"] for r in results["runs"]["SDA"]]
    assert stats["cost_median"] == pytest.approx(np.median(costs))
    assert 0 <= results["ranksum"][0]["p_two_sided"] <= 1
    assert results["versions"]["spiralid"]


def test_reproduce_on_the_real_arm(tmp_path):
    # The arm's record is a slice of a periodic sweep: it starts in motion.
    results = _reproduce_ok(
        tmp_path,
        *("--data", ARM, "--input", "u", "--output", "y", "--ts", "0.01"),
        *("--initial", "measured"),
    )
    assert results["options"]["initial"] == "measured"
    assert results["data"]["n_samples"] == 1024
    assert results["data"]["path"] == str(ARM.resolve())
    assert results["data"]["n_estimation"] == round(1024 * 2 / 3)
    ls = next(r for r in results["table2"] if r["label"] == "LS")
    assert abs(ls["fit_validation_percent"] - 95.0) <= 1.0


@pytest.mark.parametrize(
    "args, message",
    [
        (["identify", "missing.csv", "--ts", "1"], "does not exist"),
        (["identify", "ARM", "--ts", "0.01", "--input", "torque"], "columns"),
        (["identify", "ARM", "--ts", "0.01", "--na", "600"], "too short"),
        (["identify", "ARM", "--na", "-2"], "--na"),
        (["reproduce", "--data", "ARM", "--ts", "0.01", "--out", "."], "not empty"),
        (["validate", "nothing.json", "ARM"], "does not exist"),
        (["validate", "garbage.json", "ARM"], "not a valid spiralid model"),
        (["reproduce", "--ts", "0.01"], "give --data"),
        (["reproduce", "--budget", "10"], "--budget"),
        (["simulate", "--fs", "0"], "--fs"),
        (["frobnicate"], "invalid choice"),
    ],
)
def test_bad_arguments_exit_2_with_one_line(tmp_path, args, message):
    (tmp_path / "keep.txt").write_text("user data")
    (tmp_path / "garbage.json").write_text('{"theta": ["a"], "na": 1}')
    args = [str(ARM) if a == "ARM" else a for a in args]
    proc = run(*args, cwd=tmp_path)
    assert proc.returncode == 2
    # On a loaded machine a command may reach its progress line's delay
    # (``Progress``: "prefix: what, 6 s") before it refuses.
    lines = [
        line
        for line in proc.stderr.strip().splitlines()
        if not re.search(r", \d+ s$", line)
    ]
    assert len(lines) == 1, proc.stderr
    assert message in lines[0]
    assert "Traceback" not in proc.stderr
    assert (tmp_path / "keep.txt").read_text() == "user data"


def _arm_identify(tmp_path, *extra):
    from spiralid import cli

    arm = resources.files("spiralid.datasets") / "daisy_robot_arm.csv"
    argv = [*extra, "identify", str(arm), "--input", "u", "--output", "y",
            "--ts", "0.01", "--method", "ls", "--out", str(tmp_path / "m")]  # fmt: skip
    return cli.main(argv)


def test_an_internal_error_says_it_is_a_bug(tmp_path, monkeypatch, capsys):
    # A failure that is not about the user's input: exit 1, one line that
    # says it is a bug and how to report it; the traceback with --debug.
    import spiralid.sysid.models.arx as arx

    def broken(*args, **kwargs):
        raise RuntimeError("broken on purpose")

    monkeypatch.setattr(arx, "arx_least_squares", broken)
    monkeypatch.setattr(
        "spiralid.sysid.estimation.linear.local_estimators.arx_least_squares", broken
    )
    assert _arm_identify(tmp_path) == 1
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1
    assert err[0].startswith("spiralid identify: internal error (a bug in spiralid")
    assert "RuntimeError: broken on purpose" in err[0] and "--debug" in err[0]
    assert _arm_identify(tmp_path / "again", "--debug") == 1
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err and "RuntimeError" in err
    assert err.splitlines()[-1].startswith("spiralid identify: internal error")


def test_a_value_error_from_inside_numpy_is_a_bug(tmp_path, monkeypatch, capsys):
    import spiralid.sysid.estimation.linear.local_estimators as local_estimators

    def numpy_fails(*args, **kwargs):
        return np.zeros(3) + np.zeros(4)  # raises ValueError inside NumPy

    monkeypatch.setattr(local_estimators, "arx_least_squares", numpy_fails)
    assert _arm_identify(tmp_path) == 1
    assert "internal error" in capsys.readouterr().err


def test_a_bad_argument_is_the_users_error(tmp_path, capsys):
    assert _arm_identify(tmp_path, "--debug") == 0
    capsys.readouterr()
    from spiralid import cli

    arm = resources.files("spiralid.datasets") / "daisy_robot_arm.csv"
    argv = ["identify", str(arm), "--input", "u", "--output", "y", "--ts", "0.01"]
    status = cli.main([*argv, "--na", "-1", "--out", str(tmp_path / "x")])
    assert status == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("spiralid identify: error:")


def test_help_texts_say_each_default_once(tmp_path):
    simulate = run("simulate", "--help", cwd=tmp_path).stdout
    flat = " ".join(simulate.split())
    assert flat.count("default: paper") == 1 and "(default paper)" not in flat
    assert "0.3 for paper, 0.3 for bang- bang, 0.1 for prbs, 0.1 for chirp" in flat
    study = " ".join(run("study", "--help", cwd=tmp_path).stdout.split())
    assert "(default: spiralid-study)" in study and "(default: dask)" in study


def test_a_search_option_for_a_method_that_searches_nothing_is_refused(tmp_path):
    # identify() refuses the same from Python; the command must not ignore it.
    out = run("identify", "robot_arm", "--method", "LS", "--budget", "100",
              "--seed=3", "--out", "m", cwd=tmp_path)  # fmt: skip
    assert out.returncode == 2 and len(out.stderr.splitlines()) == 1
    # --seed is accepted by every method (identify's `rng`), so one command
    # line can loop over methods; --budget is a search's.
    assert "--budget does not apply to --method ls; the options" in out.stderr
    assert "the options that do: --predictor, --initial, --seed, --integrator" in (
        out.stderr
    )
    assert not (tmp_path / "m").exists()
