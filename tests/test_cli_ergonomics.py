"""The command line's ergonomics: progress on standard error (plain lines
in a log, nothing with --quiet), every default in --help, `spiralid
export`, and the files of `spiralid pareto` (units, phases, line endings).

The commands run in-process (``cli.main``), where standard error is not a
terminal, with the silence before the first progress line set to zero.
"""

import argparse
import io
import json
import re

import numpy as np
import pytest
from scipy.io import loadmat
from scipy.signal import lfilter

import spiralid.outputs.progress as progress_module
from spiralid import IdentifiedModel, cli
from spiralid.cli.export import PYTHON_LOAD
from spiralid.outputs.progress import Progress

SEARCH = ["--method", "ebsda", "--na", "2", "--nb", "2", "--nk", "1",
          "--budget", "600", "--points", "12"]  # fmt: skip
PARETO = ["--na", "2", "--nb", "2", "--nk", "1", "--budget", "300",
          "--points", "12", "--polish", "20"]  # fmt: skip


@pytest.fixture
def record(tmp_path, monkeypatch):
    """ok.csv (a second-order system, noise) in a working folder."""
    monkeypatch.chdir(tmp_path)
    rng = np.random.default_rng(0)
    u = rng.standard_normal(600)
    y = lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u) + 0.01 * rng.standard_normal(600)
    rows = "".join(f"{float(a)!r},{float(b)!r}\n" for a, b in zip(u, y, strict=True))
    (tmp_path / "ok.csv").write_text("u,y\n" + rows)
    return tmp_path


@pytest.fixture
def no_delay(monkeypatch):
    monkeypatch.setattr(progress_module, "PLAIN_DELAY", 0.0)


# -- progress -------------------------------------------------------------------


def _progress_lines(err: str, command: str) -> list[str]:
    lines = err.strip().splitlines()
    assert lines and all(line.startswith(f"spiralid {command}: ") for line in lines)
    assert "warning" not in err and "error" not in err
    return lines


def test_identify_says_its_progress_in_plain_lines(record, no_delay, capsys):
    assert cli.main(["identify", "ok.csv", "--ts", "0.01", *SEARCH, "--out", "m"]) == 0
    out, err = capsys.readouterr()
    lines = _progress_lines(err, "identify")
    assert "\r" not in err  # a log, not a terminal: no bar
    search = [line for line in lines if "estimating ARX(2, 2, 1) by ebsda: " in line]
    # The start, then every tenth of the budget: a few lines, not hundreds.
    assert 5 <= len(search) <= 12, lines
    assert re.search(r": 0/600 evaluations \(0 %\), \d+ s$", search[0]), search[0]
    percents = [int(re.search(r"\((\d+) %\)", line)[1]) for line in search]
    assert percents == sorted(percents) and percents[-1] >= 90
    assert any("validating" in line for line in lines)
    assert lines[-1].startswith("spiralid identify: done in ")
    assert "estimation cost" in out  # the summary stays on standard output
    timings = json.loads((record / "m" / "timings.json").read_text())
    assert list(timings) == [
        "load", "estimation", "search", "refine", "validation", "writing", "total"
    ]  # fmt: skip
    phases = ("load", "estimation", "validation", "writing")
    assert sum(timings[k] for k in phases) <= timings["total"] + 1e-6


def test_quiet_says_nothing(record, no_delay, capsys):
    argv = ["identify", "ok.csv", "--ts", "0.01", *SEARCH, "--out", "m", "--quiet"]
    assert cli.main(argv) == 0
    assert capsys.readouterr() == ("", "")
    # The phases are timed all the same.
    assert "validation" in json.loads((record / "m" / "timings.json").read_text())
    argv = ["pareto", "ok.csv", "--ts", "0.01", *PARETO, "--out", "p", "--quiet"]
    assert cli.main(argv) == 0
    assert capsys.readouterr() == ("", "")


def test_a_short_run_stays_silent(record, capsys, monkeypatch):
    # Nothing before PLAIN_DELAY seconds (a least-squares fit ends first).
    monkeypatch.setattr(progress_module, "PLAIN_DELAY", 600.0)
    argv = ["identify", "ok.csv", "--ts", "0.01", "--method", "ls", "--na", "2"]
    assert cli.main([*argv, "--nb", "2", "--nk", "1", "--out", "m"]) == 0
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("command", ["validate", "pareto"])
def test_other_long_commands_say_their_progress(record, no_delay, capsys, command):
    if command == "validate":
        argv = ["identify", "ok.csv", "--ts", "0.01", "--method", "ls", "--na", "2"]
        assert cli.main([*argv, "--nb", "2", "--nk", "1", "--out", "m", "--quiet"]) == 0
        argv = ["validate", "m/model.json", "ok.csv", "--out", "v"]
        said = "validating"
    else:
        argv = ["pareto", "ok.csv", "--ts", "0.01", *PARETO, "--out", "p"]
        said = "searching the front of ARX(2, 2, 1): "
    assert cli.main(argv) == 0
    lines = _progress_lines(capsys.readouterr().err, command)
    assert any(said in line for line in lines), lines
    assert lines[-1].startswith(f"spiralid {command}: done in ")


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_a_terminal_gets_one_status_line():
    stream = Terminal()
    with Progress("spiralid demo", stream=stream, delay=0.0) as progress:
        search = progress.phase("search", "searching", total=10, unit="runs")
        for done in range(1, 11):
            search(done)
        progress.phase("writing", "writing")
    text = stream.getvalue()
    assert text.count("\n") == 1 and text.endswith("\n")  # one line, rewritten
    assert "searching [" in text and "10/10 runs" in text
    assert text.rstrip().split("\r")[-1].startswith("spiralid demo: done in")


def test_a_failed_run_ends_the_line_but_says_no_done():
    for stream in (Terminal(), io.StringIO()):
        with pytest.raises(KeyboardInterrupt):
            with Progress("spiralid demo", stream=stream, delay=0.0) as progress:
                progress.phase("search", "searching", total=4)
                raise KeyboardInterrupt
        assert "done" not in stream.getvalue()
        assert stream.getvalue().endswith("\n")


def test_quiet_progress_only_times_the_phases():
    stream = Terminal()
    with Progress("spiralid demo", stream=stream, enabled=False, delay=0.0) as p:
        p.phase("load")
        p.phase("search", total=3)(2)
    assert stream.getvalue() == ""
    assert list(p.timings()) == ["load", "search", "total"]


def test_a_warning_starts_on_a_line_of_its_own():
    stream = Terminal()
    with Progress("spiralid demo", stream=stream, delay=0.0) as progress:
        progress.phase("search", "searching", total=4)(1)
        progress_module.before_message()
        stream.write("spiralid demo: warning: something\n")
        progress(2)
    lines = stream.getvalue().split("\n")
    assert lines[0].startswith("\rspiralid demo: searching [")
    assert lines[1] == "spiralid demo: warning: something"


# -- --help ---------------------------------------------------------------------


def _subcommands():
    parser = cli.build_parser()
    action = next(
        a for a in parser._actions if isinstance(a, argparse._SubParsersAction)
    )
    return action.choices.items()


def test_every_option_shows_its_default_once():
    missing, twice = [], []
    for name, parser in _subcommands():
        formatter = parser._get_formatter()
        for action in parser._actions:
            optional_positional = not action.option_strings and action.nargs == "?"
            if action.nargs == 0 or not (action.option_strings or optional_positional):
                continue  # flags (off unless given) and required arguments
            text = " ".join(formatter._expand_help(action).split())
            where = f"{name} {'/'.join(action.option_strings) or action.dest}"
            if not re.search(r"\bdefault\b", text):
                missing.append(where)
            if text.count("(default:") > 1:
                twice.append(where)
    assert not missing, missing
    assert not twice, twice


def test_the_budget_says_what_the_default_is(capsys):
    with pytest.raises(SystemExit):
        cli.main(["identify", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "(default: the method's own: 10,000 evaluations for spiral" in text
    with pytest.raises(SystemExit):
        cli.main(["pareto", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "(default: cost,frequency)" in text and "('cost'" not in text


def test_quiet_is_spelled_one_way():
    helps = set()
    for _, parser in _subcommands():
        quiet = [a for a in parser._actions if "--quiet" in a.option_strings]
        assert len(quiet) == 1
        helps.add(quiet[0].help)
    assert len(helps) == 1


# -- export ---------------------------------------------------------------------


@pytest.fixture
def model_file(record):
    argv = ["identify", "ok.csv", "--ts", "0.01", "--method", "ls", "--na", "2"]
    assert cli.main([*argv, "--nb", "2", "--nk", "1", "--out", "m", "--quiet"]) == 0
    path = record / "m" / "model.json"
    return path, IdentifiedModel.from_dict(json.loads(path.read_text()))


def test_export_round_trips_the_transfer_function(model_file, capsys):
    path, model = model_file
    dlti = model.to_dlti()
    for fmt, out in (("json", "tf.json"), ("npz", "tf.npz"), ("mat", "tf.mat")):
        assert cli.main(["export", str(path), "--to", fmt, "--out", out]) == 0
        assert capsys.readouterr().out.startswith(f"wrote {out} ({fmt}: ")
    written = json.loads(open("tf.json").read())
    assert written["num"] == [float(v) for v in dlti.num]
    assert written["den"] == [float(v) for v in dlti.den]
    assert written["ts"] == model.ts == 0.01
    assert (written["input"], written["output"]) == ("u", "y")
    with np.load("tf.npz") as z:
        np.testing.assert_array_equal(z["num"], dlti.num)
        np.testing.assert_array_equal(z["den"], dlti.den)
        assert float(z["ts"]) == model.ts
    mat = loadmat("tf.mat")
    np.testing.assert_array_equal(mat["num"], [dlti.num])  # row vectors
    np.testing.assert_array_equal(mat["den"], [dlti.den])
    # Standard output: the same JSON; and the text, with the exact numbers.
    assert cli.main(["export", str(path), "--to", "json"]) == 0
    assert json.loads(capsys.readouterr().out) == written
    assert cli.main(["export", str(path)]) == 0
    text = capsys.readouterr().out
    assert f"H(z) = {model.tf_string()}" in text
    num = next(line for line in text.splitlines() if line.startswith("num = "))
    assert json.loads(num.removeprefix("num = ")) == written["num"]
    # --to from --out's suffix.
    assert cli.main(["export", str(path), "--out", "again.json", "--quiet"]) == 0
    assert json.loads(open("again.json").read()) == written
    assert capsys.readouterr() == ("", "")


def test_export_help_gives_the_python_line(capsys):
    with pytest.raises(SystemExit):
        cli.main(["export", "--help"])
    assert PYTHON_LOAD in capsys.readouterr().out
    assert PYTHON_LOAD == (
        'IdentifiedModel.from_dict(json.load(open("model.json"))).to_control()'
    )


def test_export_refuses_a_narx_model(record, capsys):
    from spiralid.sysid import NARX, NARXModel
    from spiralid.sysid.models.narx import Scaling

    st = NARX(2, 2, 1, hidden=(2,))
    narx = NARXModel(np.zeros(st.n_params), st, Scaling(), 0.01, method="ls")
    (record / "narx.json").write_text(json.dumps(narx.to_dict()))
    assert cli.main(["export", "narx.json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith("spiralid export: error: 'narx.json' is a ")
    assert "NARX model: it has no transfer function" in err
    assert len(err.splitlines()) == 1


# -- pareto's files ---------------------------------------------------------------


def test_pareto_files_name_their_units_phases_and_end_lines_in_lf(record, capsys):
    argv = ["pareto", "ok.csv", "--ts", "0.01", *PARETO, "--out", "p"]
    assert cli.main(argv) == 0
    out = capsys.readouterr().out
    head = out.splitlines()[0]
    assert "(cost, frequency error)" in head
    assert re.search(
        r"cost [\d.e+-]+ % of rms\(y\), frequency error [\d.e+-]+ dB", head
    )
    front = (record / "p" / "front.csv").read_bytes()
    assert b"\r" not in front
    columns = front.decode().splitlines()[0].split(",")
    assert columns == [
        "point", "na", "nb", "nk", "start", "cost_pct", "frequency_dB", "knee"
    ]  # fmt: skip
    timings = json.loads((record / "p" / "timings.json").read_text())
    assert list(timings) == ["load", "search", "validation", "writing", "total"]


def test_pareto_names_the_parameter_count(record, capsys):
    argv = ["pareto", "ok.csv", "--ts", "0.01", *PARETO[6:], "--orders", "1:2"]
    assert cli.main([*argv, "--out", "p", "--quiet"]) == 0
    header = (record / "p" / "front.csv").read_text().splitlines()[0]
    assert header.split(",")[5:8] == ["cost_pct", "frequency_dB", "parameters"]
    assert "parameters (na + nb) " in (record / "p" / "summary.txt").read_text()
