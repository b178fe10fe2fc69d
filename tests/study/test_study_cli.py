"""`spiralid study` and `spiralid study-report` as a user runs them."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(sys.executable).parent / "spiralid"


def run(*args, cwd):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run(
        [str(SCRIPT), *map(str, args)], cwd=cwd, env=env, capture_output=True, text=True
    )


@pytest.mark.slow
def test_study_writes_store_and_report_then_resumes(small_spec, tmp_path):
    spec = small_spec()
    proc = run("study", spec, "--engine", "processes", "--workers", "2", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    out = tmp_path / "spiralid-study"
    assert {"study.sqlite", "report.html", "results.json"} <= {
        p.name for p in out.iterdir()
    }
    assert "Where the claim holds" in proc.stdout
    results = json.loads((out / "results.json").read_text())
    assert len(results["claims"]) == 4 and results["claim"] == ["Eb-SDA", "SDA"]
    again = run("study", spec, "--engine", "local", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert "20 runs: 20 already in" in again.stdout
    rep = run("study-report", out / "study.sqlite", "--out", "r2", cwd=tmp_path)
    assert rep.returncode == 0, rep.stderr
    report = (tmp_path / "r2" / "report.html").read_text()
    # Convergence bands, effect sizes and the anytime distributions.
    assert report.count("<img") == 3
    assert "The claim at every budget" in report


def test_show_default_prints_the_shipped_grid(tmp_path):
    proc = run("study", "--show-default", cwd=tmp_path)
    assert proc.returncode == 0 and 'method = "ebsda"' in proc.stdout
    assert not (tmp_path / "spiralid-study").exists()


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            ("seeds = 2", "seeds = 0"),
            # Quoted as the file writes it: no option of the command.
            "'seeds' must be an integer >= 1",
        ),
        (('method = "sda"', 'method = "sdb"'), "unknown method 'sdb'"),
        (("[grid]", "[grid]\nspeed = 3"), "unknown key 'speed'"),
        (
            ('kind = "rig"', 'kind = "csv"\npath = "missing.csv"'),
            "record 'rig' \\(csv\\)",
        ),
    ],
)
def test_bad_specification_fails_before_any_work(small_spec, tmp_path, edit, message):
    import re

    path = small_spec()
    path.write_text(path.read_text().replace(*edit))
    proc = run("study", path, cwd=tmp_path)
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1
    assert re.search(message, proc.stderr), proc.stderr
    assert not (tmp_path / "spiralid-study").exists()


def test_foreign_files_in_out_are_protected(small_spec, tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    proc = run("study", small_spec(), "--out", out, cwd=tmp_path)
    assert proc.returncode == 2 and "notes.txt" in proc.stderr
    assert [p.name for p in out.iterdir()] == ["notes.txt"]


def test_study_report_of_a_missing_store(tmp_path):
    proc = run("study-report", "nothing.sqlite", cwd=tmp_path)
    assert proc.returncode == 2 and "does not exist" in proc.stderr
