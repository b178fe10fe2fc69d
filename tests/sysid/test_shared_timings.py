"""The wall time of a model of several outputs is in ``timings``, as every
fitted model's is, and leaves its file on request: ``spiralid identify
--output a,b`` run twice with one seed writes the same model.json, byte for
byte, and the wall times to timings.json."""

import json
import math

import numpy as np
import pytest
from clitools import run
from two_modes import TS, record

from spiralid.sysid import ARX, IOData, identify, load_model
from spiralid.sysid.models.shared import SharedDenominatorModel


def _record(seed=0) -> IOData:
    return record(seed, n=900)


@pytest.mark.parametrize(
    ("method", "options"),
    [("spiral", {"max_nfev": 300, "rng": 1}), ("oe", {}), ("ls", {})],
)
def test_the_wall_time_is_in_timings_not_in_the_result(method, options):
    fit = identify(_record(), ARX(4, 4, 1), method=method, **options)
    assert isinstance(fit, SharedDenominatorModel)
    assert "elapsed" not in fit.result
    assert list(fit.timings) == ["total"]
    assert math.isfinite(fit.timings["total"]) and fit.timings["total"] > 0.0
    d = json.loads(json.dumps(fit.to_dict()))
    assert d["timings"] == {"total": fit.timings["total"]}
    assert "elapsed" not in d["result"]
    assert load_model(d).timings == fit.timings
    assert "timings" not in fit.to_dict(timings=False)


def test_one_seed_gives_the_same_file_without_the_timings():
    """Two fits with one seed: the wall times differ, nothing else."""
    fits = [
        identify(_record(), ARX(4, 4, 1), method="spiral", max_nfev=300, rng=7)
        for _ in range(2)
    ]
    files = [json.dumps(f.to_dict(timings=False), indent=2) for f in fits]
    assert files[0] == files[1]
    # What makes them equal is leaving the wall times out: with them the
    # files differ (perf_counter's resolution is far below a fit's time).
    with_times = [json.dumps(f.to_dict(), indent=2) for f in fits]
    assert with_times[0] != with_times[1]


@pytest.mark.parametrize("timings", [None, {}])
def test_a_file_written_before_loads_without_timings(timings):
    """Files written before the wall time moved: without a ``timings`` key,
    or with the empty one the model wrote while its wall time was the
    result's ``elapsed`` (which the file never held)."""
    fit = identify(_record(), ARX(4, 4, 1), method="oe")
    d = json.loads(json.dumps(fit.to_dict()))
    if timings is None:
        del d["timings"]
    else:
        d["timings"] = timings
    back = load_model(d)
    assert back.timings == {}
    np.testing.assert_array_equal(back.a, fit.a)
    np.testing.assert_array_equal(back.b, fit.b)


def test_identify_twice_with_one_seed_writes_the_same_model_json(tmp_path):
    rec = _record(3)
    u, y = rec.u, rec.y
    np.savez(tmp_path / "rec.npz", u=u, near=y[:, 0], far=y[:, 1], ts=TS)
    folders = ("first", "second")
    for out in folders:
        proc = run("identify", "rec.npz", "--output", "near,far", "--na", "4",
                   "--nb", "4", "--nk", "1", "--budget", "300", "--seed", "5",
                   "--out", out, "--quiet", cwd=tmp_path)  # fmt: skip
        assert proc.returncode == 0, proc.stderr
    first, second = ((tmp_path / f / "model.json").read_bytes() for f in folders)
    assert first == second
    model = json.loads(first)
    assert model["model"] == "shared-denominator" and "timings" not in model
    assert "elapsed" not in model["result"]
    # The wall times are in timings.json, as the one-output command's.
    for f in folders:
        times = json.loads((tmp_path / f / "timings.json").read_text())
        assert {"estimation", "validation", "total"} <= set(times)
        assert all(math.isfinite(v) and v >= 0.0 for v in times.values())
