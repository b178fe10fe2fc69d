"""`spiralid identify`'s --noise, --folds, --training and --horizon: each
reaches identify() as the library's own option, so the command's model is
the one the library fits from the same record with the same option."""

import numpy as np
import pytest
from clitools import run

from spiralid.sysid import ARX, NARX, IOData, identify, load_model


def _record(path) -> IOData:
    """A second-order plant with a saturating input map and a slow output
    drift (a random walk), 600 samples at 1 s."""
    rng = np.random.default_rng(3)
    u = rng.uniform(-1.0, 1.0, 600)
    y = np.zeros_like(u)
    for t in range(2, u.size):
        y[t] = 1.3 * y[t - 1] - 0.5 * y[t - 2] + np.tanh(u[t - 1]) + 0.2 * u[t - 2]
    y += np.cumsum(rng.normal(0.0, 0.02, u.size)) + rng.normal(0.0, 0.05, u.size)
    np.savetxt(path, np.c_[u, y], delimiter=",", header="u,y", comments="")
    return IOData(u, y, ts=1.0)


def _params(folder) -> np.ndarray:
    return np.asarray(load_model(folder / "model.json").params)


@pytest.mark.parametrize(
    ("flags", "structure", "options"),
    [
        (
            ["--method", "oe", "--noise", "integrated"],
            ARX(2, 2, 1),
            {"method": "oe", "noise": "integrated"},
        ),
        (
            ["--folds", "on", "--budget", "600"],
            ARX(2, 2, 1),
            {"folds": True, "max_nfev": 600},
        ),
        (
            ["--model", "narx", "--hidden", "3", "--training", "subsequences",
             "--horizon", "12", "--method", "oe"],
            NARX(2, 2, 1, hidden=(3,)),
            {"method": "oe", "training": "subsequences", "horizon": 12},
        ),
    ],
)  # fmt: skip
def test_flag_fits_the_library_model(tmp_path, flags, structure, options):
    data = _record(tmp_path / "r.csv")
    argv = ["identify", "r.csv", "--ts", "1", "--na", "2", "--nb", "2", "--nk", "1"]
    proc = run(*argv, *flags, "--fraction", "0.5", "--out", "m", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    est, _ = data.split(0.5)
    model = identify(est, structure, rng=0, **options)
    np.testing.assert_allclose(_params(tmp_path / "m"), model.params, rtol=1e-9)


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--folds", "maybe"], "must be on, off or auto"),
        (["--method", "ls", "--noise", "integrated"], "--noise does not apply"),
        (["--horizon", "12"], "--horizon does not apply"),
        (["--model", "narx", "--horizon", "12"], "training='subsequences'"),
        (["--workers", "2"], "--workers does not apply"),
    ],
)
def test_flag_refused_in_one_line(tmp_path, flags, message):
    _record(tmp_path / "r.csv")
    proc = run("identify", "r.csv", "--ts", "1", *flags, "--out", "m", cwd=tmp_path)
    assert proc.returncode == 2
    assert message in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "m").exists()
