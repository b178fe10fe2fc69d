"""The bad-input and fault matrix: every case ends with exit status 2, one line
``spiralid <command>: error: ...`` without internal names or NumPy reprs, no
warnings, and the output folder as it was (absent, or untouched).

Cases run the command line's entry point in-process (``cli.main``), which is
what the console script calls; tests/test_output_safety.py runs the script
itself under signals and concurrency.
"""

import json
import re

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid import cli
from spiralid.sysid import ARX, IOData, identify


def _csv(path, columns: dict, encoding="utf-8"):
    names = list(columns)
    rows = zip(*columns.values(), strict=True)
    text = ",".join(names) + "\n" + "".join(",".join(map(str, r)) + "\n" for r in rows)
    path.write_text(text, encoding=encoding)


@pytest.fixture
def files(tmp_path, monkeypatch):
    """A folder of good and bad records, a saved model, and user files."""
    monkeypatch.chdir(tmp_path)
    rng = np.random.default_rng(0)
    u = rng.standard_normal(600)
    y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u) + 0.01 * rng.standard_normal(600)
    u, y = [float(v) for v in u], [float(v) for v in y]
    _csv(tmp_path / "ok.csv", {"u": u, "y": y})
    _csv(tmp_path / "bom.csv", {"u": u, "y": y}, encoding="utf-8-sig")
    _csv(tmp_path / "big.csv", {"u": [v * 1e300 for v in u], "y": y})
    _csv(tmp_path / "bigy.csv", {"u": u, "y": [v * 1e300 for v in y]})
    _csv(tmp_path / "tiny.csv", {"u": u, "y": [v * 1e-300 for v in y]})
    _csv(tmp_path / "nan.csv", {"u": u, "y": [*y[:5], "nan", *y[6:]]})
    _csv(tmp_path / "inf.csv", {"u": [*u[:9], "inf", *u[10:]], "y": y})
    _csv(tmp_path / "text.csv", {"u": u, "y": [*y[:7], "oops", *y[8:]]})
    _csv(tmp_path / "short.csv", {"u": u[:6], "y": y[:6]})
    _csv(tmp_path / "const.csv", {"u": [1.0] * 600, "y": y})
    _csv(tmp_path / "zero.csv", {"u": u, "y": [0.0] * 600})
    _csv(tmp_path / "onecol.csv", {"u": u})
    _csv(
        tmp_path / "time.csv",
        {"time_s": [i * 0.02 for i in range(600)], "u": u, "y": y},
    )
    _csv(
        tmp_path / "uneven.csv",
        {"time_s": [i**1.1 for i in range(600)], "u": u, "y": y},
    )
    _csv(
        tmp_path / "fast.csv",
        {"time_s": [i * 0.005 for i in range(600)], "u": u, "y": y},
    )
    (tmp_path / "empty.csv").write_text("")
    (tmp_path / "binary.csv").write_bytes(b"\xff\xfe\x00\x81" * 50)
    (tmp_path / "rec.txt").write_text("u,y\n1,2\n")
    (tmp_path / "folder.csv").mkdir()
    np.savez(tmp_path / "evil.npz", u=np.array([object()]), y=np.zeros(1), ts=0.1)
    np.savez(tmp_path / "nots.npz", u=np.array(u), y=np.array(y))
    (tmp_path / "bad.mat").write_bytes(b"MATLAB 5.0 garbage" * 10)
    model = identify(IOData(u, y, ts=0.01), ARX(2, 2, 1), method="ls")
    (tmp_path / "model.json").write_text(json.dumps(model.to_dict()))
    (tmp_path / "garbage.json").write_text('{"theta": ["a"], "na": 1}')
    (tmp_path / "notjson.json").write_text("this is not json")
    bad_theta = {**model.to_dict(), "theta": [1e400, 0, 0, 0]}
    (tmp_path / "inf_theta.json").write_text(json.dumps(bad_theta))
    # What the user already has: never touched by a failed run.
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "notes.txt").write_text("mine")
    (tmp_path / "existing.csv").write_text("mine")
    (tmp_path / "afile").write_text("mine")
    return tmp_path


# (arguments, words the one-line message must hold). Identify and validate
# write to --out out unless the case names another target.
CASES = [
    # data files
    ("identify missing.csv --ts 1", "does not exist"),
    ("identify folder.csv --ts 1", "is not a file"),
    ("identify rec.txt --ts 1", "must end in .csv, .npz or .mat"),
    ("identify ok.csv", "--ts is required"),
    ("identify ok.csv --ts 0", "--ts: must be a positive number"),
    ("identify ok.csv --ts -1", "--ts"),
    ("identify ok.csv --ts nan", "--ts"),
    ("identify ok.csv --ts abc", "--ts"),
    ("identify ok.csv --ts 0.01 --input torque", "--input must be one of the columns"),
    ("identify ok.csv --ts 0.01 --input 7", "--input column index must be in [0, 1]"),
    ("identify onecol.csv --ts 0.01", "--output must be one of the columns"),
    ("identify text.csv --ts 0.01", "column 'y' of 'text.csv' must be numeric"),
    ("identify nan.csv --ts 0.01", "the output must be finite; got nan at sample 5"),
    ("identify inf.csv --ts 0.01", "the input must be finite; got inf at sample 9"),
    ("identify big.csv --ts 0.01", "the input must be rescaled"),
    ("identify bigy.csv --ts 0.01 --method oe", "the output must be rescaled"),
    ("identify tiny.csv --ts 0.01 --method ls", "the output must be rescaled"),
    ("identify const.csv --ts 0.01 --method ls", "constant input (1.0)"),
    ("identify const.csv --ts 0.01 --method ebsda", "constant input (1.0)"),
    ("identify zero.csv --ts 0.01 --method ls", "all-zero output"),
    ("identify short.csv --ts 0.01", "too short"),
    ("identify empty.csv --ts 0.01", "is empty"),
    ("identify binary.csv --ts 0.01", "is not a text CSV file"),
    ("identify time.csv --ts 0.01", "--ts 0.01 contradicts the time_s column"),
    ("identify uneven.csv", "not evenly spaced"),
    ("identify evil.npz", "never unpickles"),
    ("identify nots.npz", "--ts must be given"),
    ("identify bad.mat --ts 0.1", "is not a readable .mat file"),
    ("identify robot_arm --input u", "do not apply to the shipped data set"),
    # structure and search options
    ("identify ok.csv --ts 0.01 --na 600", "too short"),
    ("identify ok.csv --ts 0.01 --na -2", "--na"),
    ("identify ok.csv --ts 0.01 --nb 0", "--nb"),
    ("identify ok.csv --ts 0.01 --points 1", "--points must be an integer >= 2"),
    (
        "identify ok.csv --ts 0.01 --method ls --refine",
        "--refine applies to the search methods",
    ),
    ("identify ok.csv --ts 0.01 --budget 10", "--budget must be an integer"),
    ("identify ok.csv --ts 0.01 --iterations 0", "--iterations"),
    ("identify ok.csv --ts 0.01 --fraction 1.5", "--fraction"),
    ("identify ok.csv --ts 0.01 --fraction 1/0", "--fraction"),
    ("identify ok.csv --ts 0.01 --fraction 0.0001", "--fraction leaves an empty part"),
    ("identify ok.csv --ts 0.01 --method magic", "invalid choice"),
    ("identify ok.csv --ts 0.01 --seed -1", "--seed"),
    # output targets
    ("identify ok.csv --ts 0.01 --method ls --out afile", "is a file, not a folder"),
    ("identify ok.csv --ts 0.01 --method ls --out full", "is not empty"),
    ("simulate --out existing.csv", "exists; pass --force"),
    ("simulate --out folder.csv", "is a folder, not a file"),
    ("simulate --out rig.txt", "must end in .csv or .npz"),
    # validate
    ("validate nothing.json ok.csv --ts 0.01", "does not exist"),
    ("validate garbage.json ok.csv --ts 0.01", "not a valid spiralid model"),
    ("validate notjson.json ok.csv --ts 0.01", "not a valid spiralid model"),
    ("validate inf_theta.json ok.csv --ts 0.01", "not a valid spiralid model"),
    ("validate model.json fast.csv", "sample time"),
    ("validate model.json ok.csv --fraction 0.999", "residual-test lags"),
    ("validate model.json ok.csv --out full", "is not empty"),
    # simulate and reproduce options
    ("simulate --fs 0", "--fs"),
    ("simulate --duration -1", "--duration"),
    ("reproduce --ts 0.01", "give --data"),
    ("reproduce --budget 10", "--budget"),
    ("reproduce --seeds 0", "--seeds"),
    ("reproduce --data ok.csv --ts 0.01 --out full", "is not empty"),
    ("reproduce --data missing.csv", "does not exist"),
    ("frobnicate", "invalid choice"),
]


def _state(folder):
    return sorted(
        (str(p.relative_to(folder)), p.read_bytes() if p.is_file() else None)
        for p in folder.rglob("*")
    )


@pytest.mark.parametrize("line, words", CASES, ids=[c[0] for c in CASES])
def test_fault_ends_in_one_clear_line_and_leaves_no_trace(files, capsys, line, words):
    argv = line.split()
    if argv[0] in ("identify", "validate") and "--out" not in argv:
        argv += ["--out", "out"]
    before = _state(files)
    status = cli.main(argv)
    out, err = capsys.readouterr()
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"spiralid {argv[0]}: error: "), lines[0]
    assert words in lines[0], lines[0]
    # No internal names, no NumPy reprs, no Python internals.
    assert not re.search(r"`|np\.float|Traceback|max_nfev|n_points|\bpath\b", err)
    assert out == ""
    assert _state(files) == before  # nothing written, nothing left behind


@pytest.mark.parametrize("flag", ["--help", "-h"])
def test_help_shows_defaults_and_no_doubled_percent(capsys, flag):
    for sub in ("simulate", "identify", "validate", "reproduce"):
        with pytest.raises(SystemExit) as stop:
            cli.main([sub, flag])
        assert stop.value.code == 0
        text = capsys.readouterr().out
        assert "%%" not in text
        assert "(default:" in text
    with pytest.raises(SystemExit):
        cli.main(["identify", flag])
    text = " ".join(capsys.readouterr().out.split())
    assert "(default: 2/3)" in text and "(default: spiral)" in text


def test_readme_fraction_and_excel_csv_work(files, capsys):
    status = cli.main(
        [
            *("identify", "bom.csv", "--ts", "0.01", "--fraction", "2/3"),
            *("--method", "ls", "--na", "2", "--nb", "2", "--nk", "1"),
            *("--out", "m", "--quiet"),
        ]
    )
    assert status == 0, capsys.readouterr().err
    model = json.loads((files / "m" / "model.json").read_text())
    assert model["input_name"] == "u"
    np.testing.assert_allclose(model["theta"], [-1.5, 0.7, 1.0, 0.5], atol=0.01)
    assert capsys.readouterr() == ("", "")


def test_quiet_hostile_run_prints_only_the_error(files, capsys):
    assert cli.main(["identify", "bigy.csv", "--ts", "0.01", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "warning" not in err.lower() and len(err.strip().splitlines()) == 1


def test_validate_says_which_files_it_wrote(files, capsys):
    assert (
        cli.main(["validate", "model.json", "ok.csv", "--ts", "0.01", "--out", "v"])
        == 0
    )
    last = capsys.readouterr().out.strip().splitlines()[-1]
    written = sorted(p.name for p in (files / "v").iterdir())
    assert last.startswith("wrote ") and last.endswith(" in v")
    assert all(name in last for name in written) and "validation.json" in written


def test_detrend_recovers_the_model_under_offsets(files, capsys):
    """A constant offset on u and y biases least squares without --detrend."""
    data = IOData.from_csv(files / "ok.csv", ts=0.01)
    _csv(files / "offset.csv", {"u": list(data.u + 3.0), "y": list(data.y - 40.0)})
    common = ["--ts", "0.01", "--method", "ls", "--na", "2", "--nb", "2", "--nk", "1"]
    assert cli.main(["identify", "offset.csv", *common, "--quiet", "--out", "a"]) == 0
    assert (
        cli.main(
            ["identify", "offset.csv", *common, "--quiet", "--detrend", "--out", "b"]
        )
        == 0
    )
    raw = json.loads((files / "a" / "model.json").read_text())["theta"]
    det = json.loads((files / "b" / "model.json").read_text())["theta"]
    true = [-1.5, 0.7, 1.0, 0.5]
    np.testing.assert_allclose(det, true, atol=0.01)
    assert np.max(np.abs(np.subtract(raw, true))) > 0.05


def test_console_script_one_line_for_a_hostile_record(files):
    """The same, through the installed console script (a subprocess)."""
    from clitools import run

    proc = run("identify", "bigy.csv", "--ts", "0.01", "--method", "oe", cwd=files)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "rescaled" in proc.stderr
    assert not (files / "spiralid-identify").exists()


# -- second fault round: limits, model files, messages ------------------------


@pytest.fixture
def more_files(files):
    model = json.loads((files / "model.json").read_text())
    for name, change in {
        "nk_huge.json": {"nk": 10_000_000},
        "nk_large.json": {"nk": 30_000},
        "na_text.json": {"na": "x"},
        "theta_huge.json": {"theta": [1e308, 0, 0, 0]},
    }.items():
        (files / name).write_text(json.dumps({**model, **change}))
    (files / "latin1.json").write_bytes(b"\xff\xfe{}")
    (files / "amodel").mkdir()
    (files / "garbage.npz").write_bytes(b"hello world" * 10)
    (files / "spec.toml").write_bytes(b"\xff\xfe seeds = 2")
    cell = {"u": [1.0] * 600, "y": ["n_points", *[0.5] * 599]}
    _csv(files / "cell.csv", cell)
    return files


SECOND_ROUND = [
    ("validate nk_huge.json ok.csv --ts 0.01", "reaches 10000001 samples"),
    ("validate nk_large.json ok.csv --ts 0.01", "more than the data's N = 600"),
    ("validate na_text.json ok.csv --ts 0.01", "field 'na' must be an integer"),
    ("validate theta_huge.json ok.csv --ts 0.01", "'theta' overflows"),
    ("validate latin1.json ok.csv --ts 0.01", "is not UTF-8 text"),
    ("validate amodel ok.csv --ts 0.01", "is a folder, not a model.json"),
    ("identify garbage.npz", "is not a .npz archive"),
    ("simulate --duration 1e9", "at most 10,000,000"),
    ("simulate --fs 1e12", "shorten --duration or lower --fs"),
    ("study spec.toml --engine local", "is not UTF-8 text"),
    ("identify cell.csv --ts 0.01", "got 'n_points'"),
]


@pytest.mark.parametrize("line, words", SECOND_ROUND, ids=[c[0] for c in SECOND_ROUND])
def test_second_round_faults_end_in_one_line(more_files, capsys, line, words):
    argv = line.split()
    if argv[0] in ("identify", "validate") and "--out" not in argv:
        argv += ["--out", "out"]
    if argv[0] == "study":
        argv += ["--out", "st"]
    before = _state(more_files)
    assert cli.main(argv) == 2
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert len(lines) == 1 and words in lines[0], err
    assert "warning" not in err and "Traceback" not in err and out == ""
    assert _state(more_files) == before


def test_a_model_remembers_its_detrending(files, capsys):
    data = IOData.from_csv(files / "ok.csv", ts=0.01)
    _csv(files / "offset.csv", {"u": list(data.u + 3.0), "y": list(data.y - 40.0)})
    common = ["--ts", "0.01", "--method", "ls", "--na", "2", "--nb", "2", "--nk", "1"]
    made = ["identify", "offset.csv", *common, "--detrend", "--quiet"]
    assert cli.main([*made, "--out", "a"]) == 0
    model = json.loads((files / "a" / "model.json").read_text())
    est = data.split(2 / 3)[0]
    assert model["u_offset"] == pytest.approx(est.u.mean() + 3.0, rel=1e-12)
    assert model["y_offset"] == pytest.approx(est.y.mean() - 40.0, rel=1e-12)
    assert model["fraction"] == pytest.approx(2 / 3)
    # Validated without --detrend, the recorded offsets are applied: the fit
    # is the model's, not -1749 %.
    check = ["validate", "a/model.json", "offset.csv", "--ts", "0.01", "--fraction"]
    assert cli.main([*check, "2/3", "--out", "v"]) == 0
    fit = json.loads((files / "v" / "validation.json").read_text())["fit_percent"]
    assert fit > 95
    # A model estimated without --detrend refuses it, with the reason.
    assert cli.main(["identify", "offset.csv", *common, "--quiet", "--out", "b"]) == 0
    capsys.readouterr()
    assert cli.main(["validate", "b/model.json", "offset.csv", "--ts", "0.01",
                     "--detrend"]) == 2  # fmt: skip
    assert "estimated without it" in capsys.readouterr().err


def test_model_file_is_byte_reproducible_and_timings_apart(files):
    args = ["identify", "ok.csv", "--ts", "0.01", "--na", "2", "--nb", "2"]
    args += ["--budget", "400", "--points", "10", "--quiet"]
    assert cli.main([*args, "--out", "r1"]) == 0
    assert cli.main([*args, "--out", "r2"]) == 0
    one, two = (files / "r1" / "model.json"), (files / "r2" / "model.json")
    assert one.read_bytes() == two.read_bytes()
    assert "timings" not in json.loads(one.read_text())
    assert set(json.loads((files / "r1" / "timings.json").read_text())) >= {"total"}


def test_degenerate_models_get_order_advice():
    from spiralid.sysid import IdentifiedModel, validate

    rng = np.random.default_rng(1)
    u = rng.standard_normal(600)
    y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    data = IOData(u, y, ts=0.01)
    # A common factor (1 - 0.5 z^-1) in numerator and denominator: ARX(3, 3, 1)
    # holding an ARX(2, 2, 1) system, an exact cancellation.
    a = np.convolve([1.0, -1.5, 0.7], [1.0, -0.5])
    b = np.convolve([1.0, 0.5], [1.0, -0.5])
    cancelled = IdentifiedModel(np.r_[a[1:], b], arx=ARX(3, 3, 1), ts=0.01,
                                method="ls")  # fmt: skip
    advice = validate(cancelled, data).order_advice
    assert "cancel" in advice and "lower" in advice
    # A vanishing last denominator coefficient: a pole at the origin.
    vanishing = IdentifiedModel([-1.5, 0.7, 1e-18, 1.0, 0.5, 0.0], arx=ARX(3, 3, 1),
                                ts=0.01, method="ls")  # fmt: skip
    assert "origin" in validate(vanishing, data).summary()
    plain = IdentifiedModel([-1.5, 0.7, 1.0, 0.5], arx=ARX(2, 2, 1), ts=0.01,
                            method="ls")  # fmt: skip
    assert validate(plain, data).order_advice is None
