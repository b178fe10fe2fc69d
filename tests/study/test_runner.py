"""Running a study: a real Dask LocalCluster, resume after SIGKILL, the CLI."""

import os
import signal
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest
from patience import allowance, wait_for

from spiralid.study import (
    ResultStore,
    analyse,
    execute,
    load_records,
    load_spec,
    reproducible_part,
    run_study,
    study_tasks,
)

pytest.importorskip("distributed", reason="the study runs on Dask (spiralid[study])")

SCRIPT = Path(sys.executable).parent / "spiralid"


def _comparable(rows):
    return [reproducible_part(r) for r in rows]


def test_dask_cluster_gives_the_same_rows_as_this_process(small_spec, tmp_path):
    spec = load_spec(small_spec())
    a = run_study(spec, tmp_path / "dask.sqlite", engine="dask", workers=2)
    b = run_study(spec, tmp_path / "local.sqlite", engine="local")
    assert a.computed == b.computed == a.total == 20 and not a.failures
    with (
        ResultStore.open(tmp_path / "dask.sqlite", readonly=True) as da,
        ResultStore.open(tmp_path / "local.sqlite", readonly=True) as lo,
    ):
        assert _comparable(da.rows()) == _comparable(lo.rows())


def test_rerun_resumes_without_recomputing(small_spec, tmp_path):
    spec = load_spec(small_spec())
    store = tmp_path / "s.sqlite"
    records = load_records(spec)
    tasks = study_tasks(spec, records)
    with ResultStore.open(store, spec.digest(), spec.source) as db:
        for _, row in execute(tasks[:7], records, engine="local"):
            db.add(row)
        before = db.rows()
    run = run_study(spec, store, engine="local")
    assert (run.reused, run.computed) == (7, 13)
    with ResultStore.open(store, readonly=True) as db:
        after = {r["key"]: r for r in db.rows()}
    assert all(after[r["key"]] == r for r in before)  # same wall time: not rerun


def test_failed_runs_are_reported_and_not_stored(small_spec, tmp_path):
    text = (
        small_spec()
        .read_text()
        .replace(
            '[[optimizer]]\nlabel = "SDA"\nmethod = "sda"',
            '[[optimizer]]\nlabel = "SDA"\nmethod = "sda"\n'
            'options = { bounds_policy = "bounce" }',
        )
    )
    path = tmp_path / "bad-option.toml"
    path.write_text(text)
    run = run_study(load_spec(path), tmp_path / "s.sqlite", engine="local")
    assert len(run.failures) == 8 and run.computed == 12
    assert "bounds_policy" in run.failures[0][1]


KILL_SPEC = """
[study]
seeds = 12
budget = 6000
points = 20
na = 4
nb = 4
[grid]
predictors = ["simulation-rest"]
parametrizations = ["coefficients", "reflection"]
[[data]]
name = "rig"
kind = "rig"
[[optimizer]]
label = "SDA"
method = "sda"
[[optimizer]]
label = "Eb-SDA"
method = "ebsda"
"""


def _stored(store: Path) -> dict:
    try:
        with ResultStore.open(store, readonly=True) as db:
            return {r["key"]: r for r in db.rows()}
    except (ValueError, sqlite3.OperationalError):
        return {}


@pytest.mark.slow
def test_sigkill_of_the_scheduler_loses_nothing(tmp_path):
    spec_path = tmp_path / "kill.toml"
    spec_path.write_text(KILL_SPEC)
    store = tmp_path / "out" / "study.sqlite"
    cmd = [str(SCRIPT), "study", str(spec_path), "--out", str(tmp_path / "out")]
    cmd += ["--workers", "2", "--no-report", "--quiet"]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    # The LocalCluster's scheduler lives in the command's own process.
    hang = allowance(600)  # a safety net only, see patience.py
    proc = subprocess.Popen(cmd, env=env, start_new_session=True)
    try:
        # However long the cluster takes to start and the runs to finish.
        wait_for(lambda: len(_stored(store)) >= 6, "6 runs are stored", proc=proc,
                 seconds=300, interval=0.1)  # fmt: skip
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    finally:
        # Its worker processes are orphans now; end them too.
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    killed = _stored(store)
    total = 2 + 2 * 2 * 12
    assert 6 <= len(killed) < total, "the kill came too late to test anything"

    rerun = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=hang)
    assert rerun.returncode == 0, rerun.stderr
    final = _stored(store)
    assert len(final) == total
    # Every run stored before the kill is there, unchanged (same wall time:
    # not recomputed).
    assert all(final[k] == row for k, row in killed.items())

    spec = load_spec(spec_path)
    run_study(spec, tmp_path / "whole.sqlite", engine="processes", workers=2)
    whole = _stored(tmp_path / "whole.sqlite")
    assert _comparable(final.values()) == _comparable(whole.values())


def test_analysis_of_a_store_tests_the_claim_per_reading(small_spec, tmp_path):
    spec = load_spec(small_spec(seeds=3))
    run_study(spec, tmp_path / "s.sqlite", engine="local")
    with ResultStore.open(tmp_path / "s.sqlite", readonly=True) as db:
        res = analyse(db.rows(), spec)
    assert len(res.readings) == 4 and res.labels == ["SDA", "Eb-SDA"]
    assert len(res.claims) == 4
    for c in res.claims:
        assert c["n"] == [3, 3]
        assert c["p_holm"] >= c["p_two_sided"]
        assert 0 <= c["a12"] <= 1
    assert set(res.baselines) == {("rig", "simulation-rest"), ("rig", "one-step")}
    assert set(res.baselines["rig", "one-step"]) == {"LS", "OE"}
