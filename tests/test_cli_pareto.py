"""`spiralid pareto`: the front's files, the knee's validation, the errors."""

import csv
import json

import numpy as np
import pytest
from clitools import run

import spiralid as sid

SMALL = ("--budget", "300", "--points", "12", "--polish", "20")


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    cwd = tmp_path_factory.mktemp("pareto")
    proc = run("pareto", "robot_arm", "--na", "3", "--nb", "3", *SMALL, "--out", "f",
               cwd=cwd)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return cwd / "f", proc


def test_the_front_and_its_models_are_written(written):
    out, proc = written
    assert proc.stdout.strip().splitlines()[-1].startswith("wrote point-0")
    rows = list(csv.DictReader((out / "front.csv").open()))
    assert rows and set(rows[0]) == {
        "point", "na", "nb", "nk", "start", "cost_pct", "frequency_dB", "knee"
    }  # fmt: skip
    assert sum(int(r["knee"]) for r in rows) == 1
    costs = [float(r["cost_pct"]) for r in rows]
    assert costs == sorted(costs)
    for r in rows:
        model = sid.IdentifiedModel.from_dict(
            json.loads((out / f"point-{r['point']}" / "model.json").read_text())
        )
        assert model.is_stable and model.arx == sid.ARX(3, 3, 0)
        assert model.cost == pytest.approx(float(r["cost_pct"]), rel=1e-8)
    assert (out / "front.png").stat().st_size > 10_000


def test_the_method_default_is_identify_paretos(written):
    from spiralid.choices import DEFAULT_PARETO_METHOD, PARETO_METHOD_NAMES
    from spiralid.cli import build_parser

    cmd = build_parser()._subparsers._group_actions[0].choices["pareto"]
    method = next(a for a in cmd._actions if a.dest == "method")
    assert method.default is DEFAULT_PARETO_METHOD
    assert list(method.choices) == list(PARETO_METHOD_NAMES)
    _, proc = written
    assert f"by {DEFAULT_PARETO_METHOD} on robot_arm" in proc.stdout


def test_the_knee_is_validated_as_identify_writes_it(written):
    out, _ = written
    knee = next(
        r for r in csv.DictReader((out / "front.csv").open()) if r["knee"] == "1"
    )
    model = json.loads((out / "model.json").read_text())
    point = json.loads((out / f"point-{knee['point']}" / "model.json").read_text())
    assert model["theta"] == point["theta"]
    val = json.loads((out / "validation.json").read_text())
    assert set(val) == {"estimation", "validation"}
    assert np.isfinite(val["validation"]["fit_percent"])
    for name in ("summary.txt", "timings.json", "validation_time.png",
                 "estimation_time.png"):  # fmt: skip
        assert (out / name).is_file(), name
    assert "(the knee)" in (out / "summary.txt").read_text()


def test_orders_and_a_frequency_bound(tmp_path):
    proc = run("pareto", "robot_arm", "--orders", "2:3", "--max-frequency", "30",
               *SMALL, "--out", "o", cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    rows = list(csv.DictReader((tmp_path / "o" / "front.csv").open()))
    assert {r["na"] for r in rows} <= {"2", "3"} and "parameters" in rows[0]
    assert "lowest cost with frequency error <= 30 dB" in proc.stdout


def test_choosing_the_order_by_validation_fit(tmp_path):
    proc = run("pareto", "robot_arm", "--orders", "2:4", "--by-fit", "1", *SMALL,
               "--out", "o", cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "lowest order within 1 points of the best validation fit" in proc.stdout
    written = sid.IdentifiedModel.from_dict(
        json.loads((tmp_path / "o" / "model.json").read_text())
    )
    # The same front in the library, and the same choice on it.
    est, val = sid.datasets.robot_arm().split(2 / 3)
    front = sid.identify_pareto(est, [2, 3, 4], rng=0, max_nfev=300, n_points=12,
                                extremes_nfev=20)  # fmt: skip
    chosen = front.models[sid.choose_order(front, val, warmup=est)]
    np.testing.assert_allclose(written.theta, chosen.theta, rtol=1e-12)


@pytest.mark.parametrize(
    "args, match",
    [
        (["--by-fit", "1"], "--by-fit chooses among orders"),
        (["--orders", "2:3", "--by-fit", "1", "--max-frequency", "9"], "not both"),
        (["--objectives", "cost,gain"], "--objectives must be among"),
        (["--objectives", "cost,frequency,order"], "needs several orders"),
        (["--orders", "5:2"], "--orders"),
        (["--orders", "2:4", "--na", "3"], "--orders replaces --na"),
        # After the search: --quiet, as a long one would have said its
        # progress first.
        (["--max-frequency", "0", "--quiet"], "no front point meets"),
        (["--method", "periodic"], "--method"),
    ],
)
def test_bad_requests_exit_2_with_one_line(tmp_path, args, match):
    proc = run("pareto", "robot_arm", *SMALL, *args, "--out", "x", cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("spiralid pareto: error:")
    assert match in lines[0]
    assert not (tmp_path / "x").exists()


def test_an_existing_folder_is_refused_without_force(written, tmp_path):
    out, _ = written
    before = (out / "front.csv").read_text()
    proc = run("pareto", "robot_arm", "--na", "3", "--nb", "3", *SMALL,
               "--out", out, cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 2 and "not empty" in proc.stderr
    assert (out / "front.csv").read_text() == before
    # With --force the point folders are replaced file by file.
    proc = run("pareto", "robot_arm", "--na", "3", "--nb", "3", *SMALL,
               "--out", out, "--force", cwd=tmp_path)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert (out / "front.csv").read_text() == before  # same seed, same front
