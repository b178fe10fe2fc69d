"""`spiralid identify --output a,b`: one model of several outputs from the
command line (issue 30)."""

import json

import numpy as np
from clitools import run

from spiralid.fms import FlexibleManipulator, paper_experiment


def test_several_outputs_give_one_denominator_and_a_fit_each(tmp_path):
    rec = paper_experiment().run(FlexibleManipulator(), rng=0)
    np.savez(
        tmp_path / "rig.npz",
        u=rec.u,
        vel=rec.hub_velocity,
        acc=rec.end_acceleration,
        ts=rec.ts,
    )
    made = run("identify", "rig.npz", "--output", "vel,acc", "--na", "8", "--nb",
               "8", "--nk", "1", "--budget", "2000", "--out", "m",
               cwd=tmp_path)  # fmt: skip
    assert made.returncode == 0, made.stderr
    model = json.loads((tmp_path / "m" / "model.json").read_text())
    assert model["kind"] == "shared-denominator"
    assert model["output_names"] == ["vel", "acc"] and len(model["b"]) == 2
    freq = [m["frequency_hz"] for m in model["modes"]["modes"]]
    # The FEM's first two modes, 13.31 and 35.11 Hz, from both sensors.
    for f in (13.3105, 35.108):
        assert min(abs(np.array(freq) - f)) / f < 0.005
    report = json.loads((tmp_path / "m" / "validation.json").read_text())
    fits = report["validation"]["outputs"]
    assert set(fits) == {"vel", "acc"}
    assert "joint fit %" in made.stdout and "fit % of acc" in made.stdout


def test_an_option_a_shared_model_does_not_take_is_refused(tmp_path):
    rec = paper_experiment().run(FlexibleManipulator(), rng=0)
    np.savez(tmp_path / "rig.npz", u=rec.u, vel=rec.hub_velocity,
             acc=rec.end_acceleration, ts=rec.ts)  # fmt: skip
    out = run("identify", "rig.npz", "--output", "vel,acc", "--method", "sda",
              "--out", "m", cwd=tmp_path)  # fmt: skip
    assert out.returncode == 2 and len(out.stderr.splitlines()) == 1
    assert "takes one output" in out.stderr
    assert not (tmp_path / "m").exists()
