"""benchmarks/bbob.py at reduced size, so that the COCO script cannot rot.

Needs the ``bench`` extra (the README's test command installs it).
"""

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from patience import allowance

cocoex = pytest.importorskip(
    "cocoex", reason="the bench extra (coco-experiment) is not installed"
)

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "benchmarks" / "bbob.py"


def _bbob():
    spec = importlib.util.spec_from_file_location("bbob", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_fraction_counts_the_51_standard_targets():
    bbob = _bbob()
    assert len(bbob.TARGETS) == 51
    assert bbob.TARGETS[0] == 100.0 and np.isclose(bbob.TARGETS[-1], 1e-8)
    # 1e-3 reaches 10^2, 10^1.8, ..., 10^-3: 26 targets; 0 reaches all.
    deltas = {(2, 1, 1): 1e-3, (2, 1, 2): 0.0, (2, 3, 1): 1e3, (5, 1, 1): 0.0}
    fraction, problems = bbob.fraction_reached(deltas, 2)
    assert problems == 3
    assert fraction == pytest.approx((26 + 51 + 0) / (3 * 51), abs=1e-15)


def test_final_deltas_match_the_evaluated_costs(tmp_path, monkeypatch):
    # The parsed f - f_opt against the costs we saw minus f_opt found
    # independently, by evaluating an unobserved copy at the known optimum.
    bbob = _bbob()
    monkeypatch.chdir(tmp_path)
    cocoex.log_level("warning")
    options = "dimensions:2 function_indices:1,6 instance_indices:1,3"
    observer = cocoex.Observer("bbob", "result_folder: probe algorithm_name: probe")
    rng = np.random.default_rng(0)
    expected = {}
    for problem, twin in zip(
        cocoex.Suite("bbob", "", options),
        cocoex.Suite("bbob", "", options),
        strict=True,
    ):
        problem.observe_with(observer)
        seen = [problem(x) for x in rng.uniform(-5, 5, size=(60, 2))]
        if problem.id_function == 1:
            twin._best_parameter("print")
            x_opt = np.loadtxt("._bbob_problem_best_parameter.txt")
            expected[(2, 1, problem.id_instance)] = min(seen) - twin(x_opt)
        problem.free()
    deltas = bbob.final_deltas(tmp_path / "exdata" / "probe")
    assert set(deltas) == {(2, f, i) for f in (1, 6) for i in (1, 3)}
    for key, value in expected.items():
        assert deltas[key] == pytest.approx(value, rel=1e-8)


@pytest.mark.slow
def test_script_runs_at_reduced_size_and_cocopp_reads_its_data(tmp_path):
    out = tmp_path / "bbob"
    args = ["--dims", "2", "--functions", "1", "8", "15", "--instances", "1"]
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.run(
        [
            sys.executable,
            str(SCRIPT),
            *args,
            "--output",
            str(out),
            "--cocopp",
            "--markdown",
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=allowance(600),  # a safety net only, see patience.py
        check=False,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    bbob = _bbob()
    summary = json.loads((out / "summary.json").read_text())
    assert {row["method"] for row in summary.values()} == set(bbob.ALL_METHODS)
    for row in summary.values():
        assert row["problems"] == 3
        assert 0.0 <= row["fraction"] <= 1.0
        assert 0 < row["evaluations"] <= 3 * 2000
        assert row["method"] in proc.stdout
        # Per function, the fraction over that function's triples: the
        # three functions' mean is the whole fraction (one instance each).
        functions = row["functions"]
        assert set(functions) == {"f1", "f8", "f15"}
        assert sum(functions.values()) / 3 == pytest.approx(row["fraction"])
    assert "fraction by function, D = 2" in proc.stdout
    assert "| f15 | " in proc.stdout
    # IPOP-CMA-ES solves the 2-D sphere, Rosenbrock and Rastrigin here.
    assert summary["cma D=2"]["fraction"] > 0.9
    assert (out / "exdata" / "sda" / "D2" / "bbobexp_f8.info").is_file()
    assert (out / "ppdata" / "index.html").is_file()
    # A second run into the same folder is refused unless --force.
    again = subprocess.run(
        [sys.executable, str(SCRIPT), *args, "--output", str(out)],
        capture_output=True,
        text=True,
        env=env,
        check=False,
    )
    assert again.returncode != 0 and "not empty" in again.stderr


class _SphereHitAt:
    """A 3-D sphere that reports its final target hit from the `hit_at`-th
    evaluation on, as COCO's problems do once f - f_opt <= 1e-8."""

    dimension = 3
    lower_bounds = np.full(3, -5.0)
    upper_bounds = np.full(3, 5.0)

    def __init__(self, hit_at):
        self.hit_at = hit_at
        self.evaluations = 0

    @property
    def final_target_hit(self):
        return self.evaluations >= self.hit_at

    def __call__(self, x):
        self.evaluations += 1
        return float(np.dot(x, x))


@pytest.mark.parametrize("method", ["learned-metric+restarts", "ebsda"])
def test_a_spiral_run_ends_at_the_objective_call_that_hits_the_target(method):
    # Without a callback the search is ended from inside the objective; the
    # run returns quietly with the evaluations counted up to that call.
    bbob = _bbob()
    problem = _SphereHitAt(hit_at=300)
    objective = bbob._Timed(problem)
    bbob._spiral(problem, objective, 5000, np.random.default_rng(0), method, 10)
    # A call evaluates at most a population (ebsda: 9 moving points).
    assert 300 <= problem.evaluations < 300 + 10
    never = _SphereHitAt(hit_at=10**9)
    bbob._spiral(never, bbob._Timed(never), 2000, np.random.default_rng(0), method, 10)
    assert 2000 - 50 < never.evaluations <= 2000
