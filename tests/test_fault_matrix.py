"""The bad-input and fault matrix: every case ends with exit status 2, one line
``spiralid <command>: error: ...`` without internal names or NumPy reprs, no
warnings, and the output folder as it was (absent, or untouched).

Cases run the command line's entry point in-process (``cli.main``), which is
what the console script calls; tests/test_output_safety.py runs the script
itself under signals and concurrency.
"""

import json
import re
import warnings

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid import cli
from spiralid.sysid import ARX, NARX, IOData, NARXModel, identify
from spiralid.sysid.models.narx import Scaling


@pytest.fixture(autouse=True)
def _no_progress_lines(monkeypatch):
    """These cases read the one line a run says: progress lines come after
    PLAIN_DELAY seconds, which a loaded machine can reach."""
    from spiralid.outputs import progress

    monkeypatch.setattr(progress, "PLAIN_DELAY", 1e9)


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
    st = NARX(2, 2, 1, hidden=(2,))
    narx = NARXModel(np.zeros(st.n_params), st, Scaling(), 0.01, method="ls")
    (tmp_path / "narx.json").write_text(json.dumps(narx.to_dict()))
    (tmp_path / "garbage.json").write_text('{"theta": ["a"], "na": 1}')
    (tmp_path / "notjson.json").write_text("this is not json")
    bad_theta = {**model.to_dict(), "theta": [1e400, 0, 0, 0]}
    (tmp_path / "inf_theta.json").write_text(json.dumps(bad_theta))
    _round3_files(tmp_path, u, y)
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
        "--refine does not apply to --method ls; the options that do: --predictor",
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
    # fault round 3: models, options, pareto
    (
        "identify ok.csv --ts 0.01 --method ls --hidden 5",
        "--hidden applies to --model narx and nss, not to --model arx",
    ),
    # Abbreviated and equal to its default: still typed, still refused.
    ("identify ok.csv --ts 0.01 --method ls --hid 10", "--hidden applies to"),
    (
        "identify ok.csv --ts 0.01 --method ls --activation tanh",
        "--activation applies to --model narx, not to --model arx",
    ),
    (
        "identify ok.csv --ts 0.01 --method ls --degree 2",
        "--degree applies to --model polynomial, not to --model arx",
    ),
    (
        "identify ok.csv --ts 0.01 --method ls --holdout 0.3",
        "--holdout does not apply to --method ls; the options that do:",
    ),
    (
        "identify ok.csv --ts 0.01 --model polynomial --method ls --budget 10 --seed 5",
        "--budget does not apply to --method ls --model polynomial; the options",
    ),
    (
        "identify ok.csv --ts 0.01 --model narx --method ls --budget 5",
        "--budget does not apply to --method ls --model narx; the options that do:",
    ),
    (
        "identify ok.csv --ts 0.01 --model narx --degree 4 --terms 3",
        "--degree, --terms apply to --model polynomial, not to --model narx",
    ),
    (
        "identify ok.csv --ts 0.01 --model polynomial --method ls --hidden 3",
        "--hidden applies to --model narx and nss, not to --model polynomial",
    ),
    (
        "simulate --signal prbs --width 0.04",
        "--width applies to --signal paper and bang-bang; --signal prbs",
    ),
    ("simulate --signal chirp --width 0.1", "--signal chirp has no pulses"),
    (
        "pareto ok.csv --ts 0.01 --objectives cost,one-step --min-coherence 0.3",
        "--min-coherence does not apply to --objectives cost,one-step; the options",
    ),
    (
        "pareto ok.csv --ts 0.01 --objectives cost,one-step --max-frequency 3",
        "--max-frequency needs the frequency objective",
    ),
    ("pareto ok.csv --ts 0.01 --by-fit 1", "--by-fit chooses among orders"),
    ("pareto ok.csv --ts 0.01 --orders 3 --by-fit 1", "give --orders"),
    ("frobnicate", "invalid choice"),
    # fault round 3: data, reproduce, study
    ("identify notmat.mat --ts 0.1", "'notmat.mat' is not a readable .mat file"),
    ("identify half.mat --ts 0.1", "'half.mat' is not a readable .mat file"),
    (
        "identify badtime.csv",
        "column 'time_s' of 'badtime.csv' must be numeric; got 'abc' on line 5",
    ),
    (
        "identify gaptime.csv",
        "column 'time_s' of 'gaptime.csv' must be numeric; got '' on line 5",
    ),
    ("identify backtime.csv", "the time_s column of 'backtime.csv' must increase"),
    ("identify flattime.csv", "the time_s column of 'flattime.csv' must increase"),
    (
        "reproduce --data const.csv --ts 0.01 --workers 2",
        "the data has a constant input (1.0)",
    ),
    (
        "reproduce --data const.csv --ts 0.01 --workers 1",
        "the data has a constant input (1.0)",
    ),
    ("study-report folder.csv", "'folder.csv' is a folder, not a store file"),
    (
        "study flat.toml --engine local",
        "3 of 3 runs failed and were not stored (rerun to retry); first: LS on "
        "flat, simulation-rest: the data has a constant input",
    ),
    ("study negts.toml --engine local", "[[data]] 'flat': 'ts' must be a number > 0"),
    ("study badinput.toml", "record 'flat' (csv): 'input' must be one of the columns"),
    (
        "identify latin1.csv --ts 0.01",
        "'latin1.csv' is not UTF-8 text (byte 0xb0 on line 1, perhaps Latin-1 or "
        "Windows-1252): save it as UTF-8",
    ),
    ("identify three.csv --ts 0.01 --method ls --na 0 --nb 1", "too short"),
    ("validate model.json three.csv --ts 0.01", "the record is too short"),
    (
        "identify dup.csv --ts 0.01",
        "'dup.csv' has 2 columns named 'u' (columns 0 and 2",
    ),
    ("identify dup.csv --ts 0.01 --output 1", "'dup.csv' has 2 columns named 'u'"),
    (
        "identify complex.npz",
        "--input variable 'u' of 'complex.npz' must be real-valued",
    ),
    # export
    ("export nothing.json", "model file 'nothing.json' does not exist"),
    ("export folder.csv", "'folder.csv' is a folder, not a model.json"),
    ("export binary.csv", "'binary.csv' is not UTF-8 text"),
    ("export notjson.json", "'notjson.json' is not a valid spiralid model file"),
    ("export garbage.json", "'garbage.json' is not a valid spiralid model file"),
    ("export inf_theta.json", "not a valid spiralid model file"),
    (
        "export narx.json",
        "'narx.json' is a NARX model: it has no transfer function to export",
    ),
    ("export model.json --to npz", "--to npz writes a file: give --out FILE.npz"),
    ("export model.json --to mat", "--to mat writes a file: give --out FILE.mat"),
    ("export model.json --to json --out tf.npz", "must end in .json for --to json"),
    ("export model.json --out tf.npz --to mat", "must end in .mat for --to mat"),
    ("export model.json --out tf.json --to tf", "--to tf writes text, not .json"),
    ("export model.json --out existing.csv", "exists; pass --force"),
    ("export model.json --out full", "is a folder, not a file"),
    ("export model.json --to pdf", "invalid choice"),
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


# -- third fault round: models, options, pareto -------------------------------


@pytest.fixture
def third_files(files):
    """Model files with one bad field each, and a record of several columns
    (as `spiralid simulate` writes) with a model estimated on one of them."""
    from spiralid.sysid import NARX, NARXModel
    from spiralid.sysid.models.narx import Scaling

    model = json.loads((files / "model.json").read_text())
    for name, change in {
        "ts_zero.json": {"ts": 0},
        "ts_negative.json": {"ts": -0.01},
        "method_magic.json": {"method": "magic"},
        "kind_foo.json": {"model": "foo"},
        "fraction_5.json": {"fraction": 5},
        "gain_negative.json": {"gain": -1.0},
        "offset_nan.json": {"u_offset": float("nan")},
    }.items():
        (files / name).write_text(json.dumps({**model, **change}))
    st = NARX(2, 2, 1, hidden=(2,))
    narx = NARXModel(np.zeros(st.n_params), st, Scaling(), 0.01, method="ls")
    zeroed = {
        **narx.to_dict(),
        "scaling": dict.fromkeys(("u_shift", "u_scale", "y_shift", "y_scale"), 0.0),
    }
    (files / "narx_zeroed.json").write_text(json.dumps(zeroed))
    data = IOData.from_csv(files / "ok.csv", ts=0.01)
    noise = np.random.default_rng(1).standard_normal(data.n)
    _csv(
        files / "rig3.csv",
        {
            "time_s": [i * 0.01 for i in range(data.n)],
            "torque_Nm": list(data.u),
            "hub_angle_rad": list(data.y),
            "end_acceleration_m_s2": list(noise),
        },
    )
    named = IOData(data.u, data.y, ts=0.01, input_name="torque_Nm",
                   output_name="hub_angle_rad")  # fmt: skip
    hub = identify(named, ARX(2, 2, 1), method="ls")
    (files / "hub.json").write_text(json.dumps(hub.to_dict()))
    return files


THIRD_ROUND = [
    ("validate ts_zero.json ok.csv", "field 'ts' must be a number > 0; got 0"),
    ("validate ts_negative.json ok.csv --ts 0.01", "field 'ts' must be"),
    ("validate method_magic.json ok.csv --ts 0.01", "field 'method' must be one"),
    ("validate kind_foo.json ok.csv --ts 0.01", "field 'model' must be"),
    ("validate fraction_5.json ok.csv --ts 0.01", "field 'fraction' must be"),
    ("validate gain_negative.json ok.csv --ts 0.01", "field 'gain' must be"),
    ("validate offset_nan.json ok.csv --ts 0.01", "field 'u_offset' must be"),
    ("validate narx_zeroed.json ok.csv --ts 0.01", "field 'scaling.u_scale'"),
    # The model was estimated on torque_Nm and hub_angle_rad: not in ok.csv,
    # and u, y (model.json's) are not in rig3.csv.
    ("validate hub.json ok.csv --ts 0.01", "has no column 'torque_Nm' or"),
    ("validate model.json rig3.csv", "has no column 'u' or 'y'"),
]


@pytest.mark.parametrize("line, words", THIRD_ROUND, ids=[c[0] for c in THIRD_ROUND])
def test_third_round_faults_end_in_one_line(third_files, capsys, line, words):
    argv = [*line.split(), "--out", "out"]
    before = _state(third_files)
    assert cli.main(argv) == 2
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert len(lines) == 1 and words in lines[0], err
    assert lines[0].startswith("spiralid validate: error: ")
    assert "not a valid spiralid model" in lines[0] or "has no column" in lines[0]
    assert "warning" not in err and "Traceback" not in err and out == ""
    assert _state(third_files) == before


def test_validate_scores_the_columns_the_model_recorded(third_files, capsys):
    """Not rig3.csv's default output (end_acceleration_m_s2, here noise),
    which scored a fit of -0.00 % without a word."""
    assert cli.main(["validate", "hub.json", "rig3.csv", "--out", "v"]) == 0
    fit = json.loads((third_files / "v" / "validation.json").read_text())
    assert fit["fit_percent"] > 95
    explicit = ["--input", "torque_Nm", "--output", "hub_angle_rad"]
    assert cli.main(["validate", "hub.json", "rig3.csv", *explicit, "--out", "w"]) == 0
    same = json.loads((third_files / "w" / "validation.json").read_text())
    assert same["fit_percent"] == fit["fit_percent"]
    # What the user names still wins over the model's record.
    argv = ["validate", "hub.json", "rig3.csv", "--output", "end_acceleration_m_s2"]
    assert cli.main([*argv, "--quiet"]) == 0
    assert capsys.readouterr().err == ""


def test_an_unstable_model_s_fit_is_short_and_says_it_diverged(files, capsys):
    model = json.loads((files / "model.json").read_text())
    # A pole at z = 1.5: over 600 samples the free run grows by 1e105.
    (files / "unstable.json").write_text(
        json.dumps({**model, "theta": [-1.5, 0.0, 1.0, 0.5]})
    )
    assert cli.main(["validate", "unstable.json", "ok.csv", "--ts", "0.01"]) == 0
    row = next(
        line
        for line in capsys.readouterr().out.splitlines()
        if line.startswith("fit % (simulation, from rest)")
    )
    assert row.split()[-4:] == ["(the", "free", "run", "diverged)"], row
    value = row.split()[-5]
    assert len(value) < 12 and float(value) < -1e6, row


def test_pareto_checks_every_option_before_the_search(files, capsys, monkeypatch):
    import spiralid.sysid

    def search(*args, **kwargs):
        raise AssertionError("the search ran before the options were checked")

    monkeypatch.setattr(spiralid.sysid, "identify_pareto", search)
    for extra in (
        ["--by-fit", "1"],
        ["--orders", "2:3", "--by-fit", "1", "--max-frequency", "3"],
        ["--objectives", "cost,one-step", "--max-frequency", "3"],
        ["--objectives", "cost,one-step", "--min-coherence", "0.3"],
    ):
        status = cli.main(["pareto", "ok.csv", "--ts", "0.01", *extra, "--out", "p"])
        err = capsys.readouterr().err
        assert status == 2 and err.startswith("spiralid pareto: error: "), err
        assert len(err.splitlines()) == 1
    assert not (files / "p").exists()


def test_pareto_force_removes_the_points_of_an_earlier_larger_front(files, capsys):
    out = files / "front"
    for i in range(56):
        (out / f"point-{i}").mkdir(parents=True)
        (out / f"point-{i}" / "model.json").write_text("{}")
    (out / "point-40" / "notes.txt").write_text("mine")
    (out / "point-notes").mkdir()
    (out / "point-notes" / "model.json").write_text("mine")
    argv = ["pareto", "ok.csv", "--ts", "0.01", "--na", "2", "--nb", "2", "--nk", "1"]
    argv += ["--budget", "300", "--points", "12", "--polish", "20", "--quiet"]
    assert cli.main([*argv, "--out", str(out), "--force"]) == 0
    rows = (out / "front.csv").read_text().strip().splitlines()[1:]
    points = sorted(p.name for p in out.glob("point-[0-9]*") if p.name != "point-40")
    assert points == sorted(f"point-{i}" for i in range(len(rows)))
    assert len(rows) < 40
    for i in range(len(rows)):
        assert json.loads((out / f"point-{i}" / "model.json").read_text())["theta"]
    # What is not spiralid's stays: the user's file (its folder with it) and
    # a folder that is not a numbered point.
    assert sorted(p.name for p in (out / "point-40").iterdir()) == ["notes.txt"]
    assert (out / "point-notes" / "model.json").read_text() == "mine"
    assert capsys.readouterr() == ("", "")


def test_max_time_ends_a_search_after_the_iteration_that_passes_it():
    """Without depending on the machine's speed: a limit far below one
    iteration's time stops every search after its first iteration."""
    from spiralid.optim import minimize, minimize_pareto

    def sphere(x):
        return float(x @ x)

    box = [(-5, 5)] * 3
    capped = minimize(
        sphere, box, "ebsda", rng=0, n_points=10, options={"max_time": 1e-12}
    )
    free = minimize(sphere, box, "ebsda", rng=0, n_points=10, max_iter=1)
    assert capped.nit == 1 and capped.nfev == free.nfev == 10 + 9
    assert capped.status == 3 and capped.success
    assert "time limit" in capped.message and "max_time" in capped.message
    np.testing.assert_array_equal(capped.x, free.x)
    # A generous limit changes nothing.
    long = minimize(sphere, box, "ebsda", rng=0, n_points=10, max_iter=20,
                    options={"max_time": 1e9})  # fmt: skip
    assert long.nit == 20 and long.status == 2

    def two(x):
        return np.column_stack([x[:, 0] ** 2, (x[:, 0] - 2) ** 2])

    kw = {"n_points": 20, "rng": 0, "vectorized": True}
    front = minimize_pareto(
        two, [(-5, 5)], max_nfev=2000, options={"max_time": 1e-12}, **kw
    )
    assert front.nit == 1 and front.status == 3 and "time limit" in front.message
    first = minimize_pareto(two, [(-5, 5)], max_nfev=2000, **kw)
    assert front.nfev < first.nfev and first.status == 1


@pytest.mark.parametrize(
    ("bad", "error"),
    [
        (0, ValueError),
        (-1.0, ValueError),
        (float("nan"), ValueError),
        (float("inf"), ValueError),
        ("5", TypeError),
        (True, TypeError),
    ],
)
def test_max_time_must_be_a_positive_finite_number(bad, error):
    from spiralid.optim import minimize, minimize_pareto

    with pytest.raises(error, match=r"`max_time` must be a finite number > 0"):
        minimize(lambda x: float(x @ x), [(-1, 1)], options={"max_time": bad})
    with pytest.raises(error, match=r"`max_time` must be a finite number > 0"):
        minimize_pareto(lambda x: [x[0], -x[0]], [(-1, 1)], options={"max_time": bad})


# -- third fault round: data files, reproduce, study stores -------------------

_SPEC = """
[study]
seeds = {seeds}
budget = 40
points = 10
na = 2
nb = 2
nk = 1
baselines = {baselines}
[grid]
predictors = ["simulation-rest"]
parametrizations = ["coefficients"]
[[data]]
name = "flat"
kind = "csv"
path = "{path}"
{extra}
{optimizers}
"""
_SDA = '[[optimizer]]\nlabel = "SDA"\nmethod = "sda"'
_EBSDA = '[[optimizer]]\nlabel = "Eb-SDA"\nmethod = "ebsda"'


def _spec(seeds=1, baselines='["ls", "oe"]', path="const.csv", extra="ts = 0.01",
          optimizers=_SDA):  # fmt: skip
    return _SPEC.format(seeds=seeds, baselines=baselines, path=path, extra=extra,
                        optimizers=optimizers)  # fmt: skip


def _round3_files(folder, u, y):
    """The records and study files of the third round, in the `files` folder."""
    import io

    from scipy.io import savemat

    t = [i * 0.02 for i in range(600)]
    for name, time in {
        "badtime.csv": [*t[:3], "abc", *t[4:]],
        "gaptime.csv": [*t[:3], "", *t[4:]],
        "backtime.csv": [-v for v in t],
        "flattime.csv": [1.0] * 600,
    }.items():
        _csv(folder / name, {"time_s": time, "u": u, "y": y})
    _csv(folder / "latin1.csv", {"u (\xb0C)": u, "y": y}, encoding="latin-1")
    _csv(folder / "three.csv", {"u": u[:3], "y": y[:3]})
    rows = "".join(f"{a},{b},{2 * a}\n" for a, b in zip(u, y, strict=True))
    (folder / "dup.csv").write_text("u,y,u\n" + rows)
    np.savez(folder / "complex.npz", u=np.array(u) * (1 + 1j), y=np.array(y), ts=0.1)
    (folder / "notmat.mat").write_text("not a mat")
    whole = io.BytesIO()
    savemat(whole, {"u": np.array(u), "y": np.array(y), "ts": 0.1})
    (folder / "half.mat").write_bytes(whole.getvalue()[: len(whole.getvalue()) // 2])
    (folder / "flat.toml").write_text(_spec())
    (folder / "negts.toml").write_text(_spec(extra="ts = -1"))
    (folder / "badinput.toml").write_text(_spec(extra='ts = 0.01\ninput = "torque"'))


@pytest.fixture
def stores(files):
    """A study's complete store (4 runs), copies of it killed at 0 and at 3
    rows, a SQLite file of something else and an empty file."""
    import shutil
    import sqlite3

    from spiralid.study import load_spec, run_study

    both = f"{_EBSDA}\n{_SDA}"
    (files / "ok.toml").write_text(
        _spec(seeds=2, baselines="[]", path="ok.csv", optimizers=both)
    )
    run = run_study(load_spec(files / "ok.toml"), files / "study" / "study.sqlite",
                    engine="local")  # fmt: skip
    assert (run.computed, run.failures) == (4, [])
    for name, keep in (("killed", 0), ("partial", 3)):
        (files / name).mkdir()
        copy = files / name / "study.sqlite"
        shutil.copy(files / "study" / "study.sqlite", copy)
        with sqlite3.connect(copy) as db:
            keys = [k for (k,) in db.execute("SELECT key FROM runs ORDER BY key")]
            db.executemany(
                "DELETE FROM runs WHERE key = ?", [(k,) for k in keys[keep:]]
            )
        db.close()
    db = sqlite3.connect(files / "other.sqlite")
    db.execute("CREATE TABLE notes (text TEXT)")
    db.close()
    (files / "empty.sqlite").write_bytes(b"")
    return files


STORE_FAULTS = [
    ("study-report killed/study.sqlite", "holds no finished run: its study stopped "
     "before the first of its 4 runs finished"),
    ("study-report other.sqlite", "'other.sqlite' is not a spiralid store"),
    ("study-report empty.sqlite", "'empty.sqlite' is an empty file"),
    ("study-report study", "'study' is a folder, not a store file; give the store "
     "in it, 'study/study.sqlite'"),
    ("study ok.toml --store other.sqlite", "'other.sqlite' is not a spiralid store"),
]  # fmt: skip


@pytest.mark.parametrize("line, words", STORE_FAULTS, ids=[c[0] for c in STORE_FAULTS])
def test_bad_stores_end_in_one_line_and_write_nothing(stores, capsys, line, words):
    argv = [*line.split(), "--out", "rep"]
    if argv[0] == "study":
        argv += ["--engine", "local"]
    before = _state(stores)
    assert cli.main(argv) == 2
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"spiralid {argv[0]}: error: ")
    assert words in lines[0], lines[0]
    assert "Traceback" not in err and "warning" not in err and out == ""
    assert _state(stores) == before


def test_a_partial_store_is_reported_with_what_is_missing(stores, capsys):
    argv = ["study-report", "partial/study.sqlite", "--out", "rep"]
    assert cli.main(argv) == 0
    out, err = capsys.readouterr()
    assert err.strip().splitlines() == [
        "spiralid study-report: warning: the store holds 3 of the study's 4 runs "
        "(1 missing: the study stopped early or runs failed); this report covers "
        "what the store holds only; rerun the study to compute the rest"
    ]
    assert out.startswith("Partial study: the store holds 3 of the study's 4 runs")
    results = json.loads((stores / "rep" / "results.json").read_text())
    assert results["runs"] == {"stored": 3, "expected": 4}
    assert "Partial study:" in (stores / "rep" / "report.html").read_text()
    # --quiet: the same files, nothing said.
    assert cli.main([*argv[:-1], "rep2", "--quiet"]) == 0
    assert capsys.readouterr() == ("", "")
    assert {p.name for p in (stores / "rep2").iterdir()} == {
        p.name for p in (stores / "rep").iterdir()
    }
    # The complete store: no word of missing runs.
    assert cli.main(["study-report", "study/study.sqlite", "--out", "rep3"]) == 0
    out, err = capsys.readouterr()
    assert err == "" and "Partial" not in out
    assert "Partial" not in (stores / "rep3" / "report.html").read_text()


def test_library_errors_of_round_3_name_the_argument(files):
    from spiralid.datasets import read_record

    with pytest.raises(ValueError, match="`u` must be real-valued; got complex"):
        IOData(np.ones(5) * 1j, np.ones(5), ts=1.0)
    with pytest.raises(ValueError, match="`y` must be real-valued"):
        IOData(np.ones(5), np.ones(5, dtype=complex), ts=1.0)
    with pytest.raises(ValueError, match=r"`input` variable 'u' of .* real-valued"):
        IOData.from_npz(files / "complex.npz")
    with pytest.raises(ValueError, match=r"dup.csv' has 2 columns named 'u'.*`input`"):
        IOData.from_csv(files / "dup.csv", ts=1.0)
    # By index, the duplicated name is no question.
    assert IOData.from_csv(files / "dup.csv", input=2, ts=1.0).input_name == "u"
    with pytest.raises(ValueError, match=r"half.mat' is not a readable .mat file"):
        IOData.from_mat(files / "half.mat")
    with pytest.raises(ValueError, match=r"the time_s column of .*must increase"):
        read_record(files / "flattime.csv")
    with pytest.raises(ValueError, match=r"not UTF-8 text \(byte 0xb0 on line 1"):
        IOData.from_csv(files / "latin1.csv", ts=1.0)
    np.savez(files / "negts.npz", u=np.ones(5), y=np.ones(5), ts=-1.0)
    with pytest.raises(ValueError, match=r"the variable 'ts' of .*negts.npz' must be"):
        read_record(files / "negts.npz")
    # A file's bad ts is refused, not replaced by the caller's default.
    with pytest.raises(ValueError, match="the variable 'ts'"):
        read_record(files / "negts.npz", default_ts=0.5)
    assert read_record(files / "nots.npz", default_ts=0.5).ts == 0.5


# -- fourth fault round: several outputs and their model files -----------------


def _two_outputs(tmp_path):
    """bias.csv: one input, outputs vel and acc with offsets (5 and -3), as
    a rig's velocity and accelerometer; the same with renamed columns; and
    an NPZ whose second output is half as long."""
    rng = np.random.default_rng(0)
    u = rng.standard_normal(900)
    den = np.poly([0.9 * np.exp(0.5j), 0.9 * np.exp(-0.5j)]).real
    vel = lfilter([0.0, 1.0, 0.3], den, u) + 5.0 + 0.01 * rng.standard_normal(900)
    acc = lfilter([0.0, 0.2, -0.4], den, u) - 3.0 + 0.01 * rng.standard_normal(900)
    t = [i * 0.01 for i in range(900)]
    _csv(tmp_path / "bias.csv", {"time_s": t, "u": list(u), "vel": list(vel),
                                 "acc": list(acc)})  # fmt: skip
    _csv(tmp_path / "renamed.csv", {"time_s": t, "u": list(u), "v2": list(vel),
                                    "a2": list(acc)})  # fmt: skip
    np.savez(tmp_path / "y2d.npz", u=u, vel=vel, accshort=acc[:450], ts=0.01)


@pytest.fixture(scope="module")
def shared_files(tmp_path_factory):
    """A folder with the records of `_two_outputs`, and a shared-denominator
    model identified on bias.csv by the command line with --detrend (its
    file records each output's offset), with hand-edited copies."""
    folder = tmp_path_factory.mktemp("fourth")
    _two_outputs(folder)
    argv = ["identify", str(folder / "bias.csv"), "--output", "vel,acc", "--detrend",
            "--method", "ls", "--na", "2", "--nb", "2", "--nk", "1", "--quiet",
            "--out", str(folder / "o")]  # fmt: skip
    assert cli.main(argv) == 0
    model = json.loads((folder / "o" / "model.json").read_text())
    for name, change in {
        "units_short.json": {"output_units": [""]},
        "integrators_text.json": {"integrators": "20"},
        "integrators_half.json": {"integrators": [0.5, 0]},
        "integrators_three.json": {"integrators": [3, 0]},
        "nk_half.json": {"structure": {**model["structure"], "nk": 1.5}},
        "covariance_small.json": {"covariance": [[1.0]]},
        "ts_text.json": {"ts": "0.002"},
        "ts_negative.json": {"ts": -0.01},
        "b_text.json": {"b": [["1", 0.0], [0.0, 1.0]]},
        "offsets_short.json": {"y_offsets": [5.0]},
        "names_twice.json": {"output_names": ["vel", "vel"]},
    }.items():
        (folder / name).write_text(json.dumps({**model, **change}))
    return folder


FOURTH_ROUND = [
    ("identify y2d.npz --output vel,accshort", "must have the same length"),
    ("validate o/model.json y2d.npz --output vel,accshort", "'accshort' 450"),
    ("validate units_short.json bias.csv", "field 'output_units' must be a list of 2"),
    ("validate integrators_text.json bias.csv", "field 'integrators' must be a list"),
    ("validate integrators_half.json bias.csv", "field 'integrators' must be whole"),
    ("validate integrators_three.json bias.csv", "must be counts in [0, 2]"),
    ("validate nk_half.json bias.csv", "field 'structure.nk' must be an integer"),
    ("validate covariance_small.json bias.csv", "field 'covariance' must be an array"),
    ("validate ts_text.json bias.csv", "field 'ts' must be a number > 0; got '0.0"),
    ("validate ts_negative.json bias.csv", "field 'ts' must be a number > 0; got -0"),
    ("validate b_text.json bias.csv", "field 'b' must be an array of 2 x 2 numbers"),
    ("validate offsets_short.json bias.csv", "field 'y_offsets' must be a list of 2"),
    ("validate names_twice.json bias.csv", "must name each of the 2 outputs once"),
    ("validate o/model.json bias.csv --output acc", "must name the model's 2 outputs"),
    ("validate o/model.json renamed.csv", "in the model's order"),
    ("export o/model.json", "is a model of 2 outputs (vel, acc) with one denominator"),
    ("identify bias.csv --output vel,acc --integrator 3,1 --na 4",
     "--integrator must be at most 2 known integrators per output; got (3, 1)"),
    ("identify bias.csv --output vel,acc --refine",
     "--refine does not apply to --method spiral on 2 outputs"),
    ("identify bias.csv --output vel,acc --method ebsda", "--method ebsda takes one"),
    ("pareto bias.csv --output vel,acc", "this command takes one output"),
    ("reproduce --data bias.csv --output vel,acc", "this command takes one output"),
]  # fmt: skip


@pytest.mark.parametrize("line, words", FOURTH_ROUND, ids=[c[0] for c in FOURTH_ROUND])
def test_fourth_round_faults_end_in_one_line(
    shared_files, capsys, monkeypatch, line, words
):
    monkeypatch.chdir(shared_files)
    argv = line.split()
    if argv[0] in ("identify", "validate", "pareto", "reproduce"):
        argv += ["--out", "out"]
    before = _state(shared_files)
    assert cli.main(argv) == 2
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert len(lines) == 1 and words in lines[0], err
    assert lines[0].startswith(f"spiralid {argv[0]}: error: ")
    assert not re.search(r"`|Traceback|internal error|weights", err)
    assert out == ""
    assert _state(shared_files) == before


def _fits(folder) -> dict:
    report = json.loads((folder / "validation.json").read_text())
    return {name: v["fit_percent"] for name, v in report["outputs"].items()}


def test_offsets_and_outputs_are_matched_by_name(shared_files, monkeypatch):
    """The offsets a model file records follow the outputs' names, not the
    columns' order (`--output acc,vel` scored vel at -5320 %), and renamed
    columns are taken in the order --output gives them."""
    monkeypatch.chdir(shared_files)
    model = json.loads((shared_files / "o" / "model.json").read_text())
    assert model["fraction"] == pytest.approx(2 / 3)
    assert model["y_offsets"][0] > 4 and model["y_offsets"][1] < -2
    runs = {
        "plain": [],
        "swapped": ["--output", "acc,vel"],
        "renamed": ["--output", "v2,a2"],
    }
    fits = {}
    for name, extra in runs.items():
        data = "renamed.csv" if name == "renamed" else "bias.csv"
        argv = ["validate", "o/model.json", data, *extra, "--quiet", "--out", name]
        assert cli.main(argv) == 0
        fits[name] = _fits(shared_files / name)
    assert fits["plain"]["vel"] > 95 and fits["plain"]["acc"] > 95
    assert fits["swapped"] == fits["plain"] == fits["renamed"]


def test_outputs_whose_names_become_one_file_name_keep_their_figures(
    tmp_path, monkeypatch
):
    """'acc x' and 'acc.x' both made acc_x: half the figures were lost and
    the report showed one output's twice."""
    monkeypatch.chdir(tmp_path)
    _two_outputs(tmp_path)
    text = (tmp_path / "bias.csv").read_text().replace("vel,acc", "acc x,acc.x", 1)
    (tmp_path / "names.csv").write_text(text)
    argv = ["identify", "names.csv", "--output", "acc x,acc.x", "--method", "ls",
            "--na", "2", "--nb", "2", "--nk", "1", "--quiet", "--out", "o"]  # fmt: skip
    assert cli.main(argv) == 0
    figures = sorted(p.name for p in (tmp_path / "o").glob("validation_acc_x*.png"))
    kinds = [f.removeprefix("validation_acc_x_") for f in figures if "-2_" not in f]
    assert len(kinds) >= 4
    assert figures == sorted(
        [f"validation_acc_x_{k}" for k in kinds]
        + [f"validation_acc_x-2_{k}" for k in kinds]
    )
    page = (tmp_path / "o" / "report.html").read_text(encoding="utf-8")
    assert page.count("<img") == 2 * len(kinds) + 1  # and the diagram
    argv = ["validate", "o/model.json", "names.csv", "--quiet", "--out", "v"]
    assert cli.main(argv) == 0
    assert len(list((tmp_path / "v").glob("*.png"))) == 2 * len(kinds)


def test_the_modes_table_shows_whole_output_names():
    from spiralid.sysid.models.shared import SharedDenominatorModel

    names = ("end_point_acceleration_x", "end_point_acceleration_y")
    model = SharedDenominatorModel(
        a=np.poly([0.9 * np.exp(0.5j), 0.9 * np.exp(-0.5j)]).real[1:],
        b=[[1.0, 0.3], [0.2, -0.4]],
        arx=ARX(2, 2, 1),
        ts=0.01,
        output_names=names,
    )
    head, row = str(model.modes).splitlines()
    assert all(n in head for n in names)
    assert len(row) == len(head)


def test_mode_shares_do_not_move_with_output_units():
    """residuez's absolute tolerances moved the shares of an output in
    1e-9 units (78.7/21.3 % against 73.7/26.3 %); a share is a ratio."""
    from spiralid.sysid.models.modes import mode_table

    poles = [0.95 * np.exp(0.3j), 0.9 * np.exp(1.0j)]
    a = np.poly([*poles, *np.conj(poles)]).real[1:]
    b = np.array([0.0, 1.0, 0.3, -0.2, 0.1])
    unit = mode_table(a, b, 0.01).share
    for scale in (1e-9, 3e-8, 1e6):
        np.testing.assert_allclose(
            mode_table(a, b * scale, 0.01).share, unit, rtol=1e-9
        )


def test_an_interrupt_turned_into_another_error_is_an_interrupt(monkeypatch, capsys):
    """A Ctrl-C inside a compiled kernel came back as a SystemError, which
    the command reported as a bug."""
    import os
    import signal
    import time

    from spiralid.cli import validate

    def run(args, argv):
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(5)
        except KeyboardInterrupt:
            raise SystemError("returned a result with an exception set") from None
        return 0

    monkeypatch.setattr(validate, "run", run)
    # As a shell starts the command: an earlier in-process interrupt left
    # SIGINT ignored (the command's exit keeps late signals out).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        assert cli.main(["validate", "m.json", "d.csv"]) == 130
    finally:
        signal.signal(signal.SIGINT, previous)
    out, err = capsys.readouterr()
    assert err.strip().splitlines() == ["spiralid validate: interrupted"]
    assert out == ""


def test_library_errors_of_round_4_name_the_argument():
    from spiralid.sysid import identify_pareto
    from spiralid.sysid.models.shared import SharedDenominatorModel

    rng = np.random.default_rng(0)
    u = rng.standard_normal(300)
    data = IOData(u, lfilter([0.0, 1.0], [1.0, -0.5], u), ts=0.01)
    with pytest.raises(
        ValueError, match=r"`nk` builds .* has its own nk = 1; got nk = 3"
    ):
        identify_pareto(data, ARX(2, 2, 1), nk=3)
    model = SharedDenominatorModel(
        a=[-0.5], b=[[1.0], [2.0]], arx=ARX(1, 1, 1), ts=0.01, output_names=("a", "b")
    )
    np.testing.assert_array_equal(
        model.output_model(np.int64(1)).theta, model.output_model("b").theta
    )
    with pytest.raises(ValueError, match=r"`which` must be an index in \[0, 1\]"):
        model.output_model(2)
    with pytest.raises(ValueError, match="`which` must be one of"):
        model.output_model("c")


# -- fourth fault round: NARX selection ---------------------------------------


@pytest.fixture
def narx_files(files):
    """nl.csv: a second-order system behind a saturating input map (true
    lags 2), 900 samples at ts 1 s."""
    rng = np.random.default_rng(7)
    u = rng.uniform(-1.0, 1.0, 900)
    y = np.zeros_like(u)
    for t in range(2, u.size):
        y[t] = 1.2 * y[t - 1] - 0.5 * y[t - 2] + np.tanh(u[t - 1]) + 0.2 * u[t - 2]
    _csv(files / "nl.csv", {"u": [float(v) for v in u], "y": [float(v) for v in y]})
    return files


def _candidate_lines(out: str) -> list[str]:
    """The lines of --by-fit's list: one per candidate, indented."""
    head = out.index("chosen by validation fit")
    block = out[head:].split("\n\n", 1)[0]
    return [line for line in block.splitlines()[1:] if line.startswith("  ")]


@pytest.mark.parametrize(
    "flags, structures",
    [
        # Three lags, ten terms each: one size, which hid two of them.
        (
            "--model polynomial --degree 2 --terms 10 --lags 2,3,4",
            [("polynomial", n, None) for n in (2, 3, 4)],
        ),
        # NARX(1, 1, 0, hidden=(5,)) and NARX(3, 3, 0, hidden=(2,)) share
        # 23 parameters.
        (
            "--model narx --lags 1,3 --hidden 2,5",
            [("narx", n, h) for n in (1, 3) for h in (2, 5)],
        ),
    ],
    ids=["polynomial", "narx"],
)
def test_by_fit_lists_and_validates_every_candidate(
    narx_files, capsys, flags, structures
):
    """Every candidate is listed with its validation fit, worked out here by
    fitting and validating each one; the chosen one is the smallest within
    the tolerance of the best, the best-fitting of its size."""
    from spiralid.sysid import PolynomialNARX, validate

    argv = ["identify", "nl.csv", *flags.split(), "--nk", "0", "--method", "ls",
            "--by-fit", "1", "--ts", "1", "--seed", "0", "--out", "m"]  # fmt: skip
    assert cli.main(argv) == 0
    out = capsys.readouterr().out
    est, val = IOData.from_csv(narx_files / "nl.csv", ts=1.0).split(2 / 3)
    models = [
        identify(est, NARX(n, n, 0, hidden=(h,)), method="ls", rng=0)
        if kind == "narx"
        else identify(est, PolynomialNARX(n, n, 0, degree=2, n_terms=10), method="ls")
        for kind, n, h in structures
    ]
    fits = [validate(m, val, warmup=est).fit_percent for m in models]
    sizes = [m.params.size for m in models]
    assert len(set(sizes)) < len(sizes), "the case must hold candidates of one size"
    listed = _candidate_lines(out)
    assert len(listed) == len(models), out
    for m, size, fit in zip(models, sizes, fits, strict=True):
        line = f"  {m.structure}: {size} parameters, validation fit {fit:.2f} %"
        assert any(row.startswith(line) for row in listed), (line, listed)
    ok = [i for i, f in enumerate(fits) if f >= max(fits) - 1.0]
    smallest = min(sizes[i] for i in ok)
    want = max((i for i in ok if sizes[i] == smallest), key=lambda i: fits[i])
    chosen = [row for row in listed if row.endswith("  <- chosen")]
    assert len(chosen) == 1 and chosen[0].startswith(f"  {models[want].structure}:")
    if len(set(sizes)) == 1:
        # One size: the choice is the best validation fit.
        assert fits[want] == max(fits)
    saved = json.loads((narx_files / "m" / "model.json").read_text())
    assert NARXModel.from_dict(saved).structure == models[want].structure


def _two_of_one_size(files):
    """Two ARX(2, 2, 1) models, 4 parameters each: one fitted on ok.csv's
    estimation part (a little noise), one on a noiseless record of another
    second-order system (which it fits exactly: the lower estimation
    cost)."""
    data = IOData.from_csv(files / "ok.csv", ts=0.01)
    est, val = data.split(2 / 3)
    u = np.random.default_rng(5).standard_normal(400)
    y = lfilter([0.0, 0.3, 0.2], [1.0, 0.4, 0.3], u)
    other = identify(IOData(u, y, ts=0.01), ARX(2, 2, 1), method="ls")
    right = identify(est, ARX(2, 2, 1), method="ls")
    return [other, right], est, val


def test_choose_order_validates_every_model_of_one_size(files):
    from spiralid.sysid import choose_order, fits_by_order, validate, validation_fits

    models, est, val = _two_of_one_size(files)
    assert models[0].params.size == models[1].params.size
    assert models[0].cost < 1e-6 * models[1].cost
    fits = [validate(m, val, warmup=est).fit_percent for m in models]
    assert fits[1] > 95 > fits[0] + 50
    assert validation_fits(models, val, warmup=est) == [
        (4, 0, fits[0]),
        (4, 1, fits[1]),
    ]
    # Not the lower estimation cost: the better validation fit.
    assert choose_order(models, val, warmup=est, tolerance=1.0) == 1
    # A dict keyed by size cannot hold both: refused, not one dropped.
    with pytest.raises(ValueError, match=r"`front` holds 2 models of 4 parameters"):
        fits_by_order(models, val, warmup=est)


def _narx_record(n=300, constant_end=0):
    u = np.random.default_rng(0).standard_normal(n)
    y = np.tanh(lfilter([0.0, 0.5], [1.0, -0.8], u))
    if constant_end:
        y[-constant_end:] = 1.0
    return IOData(u, y, ts=0.01)


SMALL_BOX = dict(lags=(1, 2), hidden=(1, 2), n_points=3, rng=0)


@pytest.mark.parametrize(
    "data, kwargs, words",
    [
        # round(0.001 * 300) = 0 samples held back: the fit was nan.
        (_narx_record(), dict(holdback=0.001, budget=2),
         "`holdback` = 0.001 holds back 0 of the 300 samples of `data`: too few"),
        (_narx_record(), dict(holdback=1 / 300, budget=2),
         "holds back 1 of the 300 samples"),
        # A constant held-back output: the fit was -inf.
        (_narx_record(constant_end=75), dict(budget=2),
         "the held-back output (the last 75 samples of `data`, `holdback` = 0.25) "
         "is constant, every sample 1.0: no variance"),
        # NARX(4, 4, 1, hidden=(8,)): 8 x 8 input weights, 8 biases, 8 output
        # weights, 1 bias and 8 linear terms are 89 parameters, after 4
        # initial samples; 80 * 3/4 leave 60.
        (_narx_record(80), dict(lags=(1, 4), hidden=(1, 8), budget=2),
         "needs at least 94 samples (89 parameters after 4 initial samples, plus "
         "one); got 60 before the held-back part (`holdback` = 0.25), for the "
         "largest choice of `lags` and `hidden`"),
    ],
)  # fmt: skip
def test_choose_narx_refuses_what_it_cannot_score_in_one_line(data, kwargs, words):
    from spiralid.sysid import choose_narx

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError) as err:
            choose_narx(data, **{**SMALL_BOX, **kwargs})
    message = str(err.value)
    assert words in message and "\n" not in message, message
    assert "np.float" not in message


def test_choose_narx_with_a_budget_of_one_trains_one_choice(monkeypatch):
    """budget=1 is one training (and the refit): the search's first point,
    scored here again from the model it trained by fit_percent."""
    from spiralid.sysid import choose_narx, fit_percent
    from spiralid.sysid.estimation.narx import choice as narx_choice

    trained = []

    def recording(data, structure, **options):
        model = identify(data, structure, **options)
        trained.append((data.n, structure, options["decay"], model))
        return model

    monkeypatch.setattr(narx_choice, "identify", recording)
    data = _narx_record()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = choose_narx(data, **{**SMALL_BOX, "budget": 1})
    assert res.success and res.nfev == 1 and len(res.trials) == 1
    assert res.message == "The budget of 1 training was spent."
    # One training on the first 225 samples, then the refit on all 300.
    (n_train, st, decay, model), (n_all, refit_st, refit_decay, refit) = trained
    assert (n_train, n_all) == (225, 300)
    assert st == refit_st == res.structure and decay == refit_decay == res.decay
    assert refit is res.model
    held = fit_percent(data.y[225:], model.simulate(data.u)[225:])
    assert np.isfinite(held) and res.fit == pytest.approx(held, abs=1e-9)
    n, h, d = res.trials[0][:3]
    assert res.trials[0][3] == res.fit and tuple(res.x) == (n, h, d)
    assert st == NARX(n, n, 1, hidden=(h,)) and res.fun == pytest.approx(100 - res.fit)
