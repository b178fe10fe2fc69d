"""`spiralid identify --output a,b`: one model of several outputs from the
command line (issue 30)."""

import html
import json
import re

import numpy as np
import pytest
from clitools import run

from spiralid.fms import FlexibleManipulator, paper_experiment
from spiralid.sysid.models.modes import interval_format


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """`spiralid identify --output vel,acc` on the rig's record: the run and
    its folder."""
    tmp_path = tmp_path_factory.mktemp("shared")
    rec = paper_experiment().run(FlexibleManipulator(), rng=0)
    np.savez(
        tmp_path / "rig.npz",
        u=rec.u,
        vel=rec.hub_velocity,
        acc=rec.end_acceleration,
        ts=rec.ts,
    )
    out = run("identify", "rig.npz", "--output", "vel,acc", "--na", "8", "--nb",
              "8", "--nk", "1", "--budget", "2000", "--out", "m",
              cwd=tmp_path)  # fmt: skip
    assert out.returncode == 0, out.stderr
    return out, tmp_path / "m"


def test_several_outputs_give_one_denominator_and_a_fit_each(made):
    made, folder = made
    model = json.loads((folder / "model.json").read_text())
    assert model["model"] == "shared-denominator"
    assert model["output_names"] == ["vel", "acc"] and len(model["b"]) == 2
    freq = [m["frequency_hz"] for m in model["modes"]["modes"]]
    # The FEM's first two modes, 13.31 and 35.11 Hz, from both sensors.
    for f in (13.3105, 35.108):
        assert min(abs(np.array(freq) - f)) / f < 0.005
    report = json.loads((folder / "validation.json").read_text())
    fits = report["validation"]["outputs"]
    assert set(fits) == {"vel", "acc"}
    assert "joint fit %" in made.stdout and "fit % of acc" in made.stdout
    # The summary's modes table: every mode's interval, as model.json has it.
    assert "Shared modes" in made.stdout
    for m in model["modes"]["modes"]:
        lo, hi = m["frequency_interval_hz"]
        fmt = interval_format((lo, hi))
        assert f"[{lo:{fmt}}, {hi:{fmt}}]" in made.stdout
        assert format(lo, fmt) != format(hi, fmt)


def _cells(page: str) -> list[str]:
    return [html.unescape(c) for c in re.findall(r"<td>(.*?)</td>", page)]


def _intervals(cells: list[str]) -> list[tuple[float, float]]:
    """The table cells that hold an interval "[lo, hi]", as numbers."""
    found = [re.fullmatch(r"\[(\S+), (\S+)\]", c) for c in cells]
    return [(float(m[1]), float(m[2])) for m in found if m]


def _assert_shown(shown, exact) -> None:
    """An interval as the table shows it: its ends to the digits printed,
    and told apart (a rig mode's interval is 1e-5 Hz wide)."""
    np.testing.assert_allclose(shown, exact, rtol=5e-4, atol=5e-5)
    assert shown[0] < shown[1]


def test_the_report_holds_the_modes_the_fits_and_the_diagram(made):
    _, folder = made
    page = (folder / "report.html").read_text(encoding="utf-8")
    model = json.loads((folder / "model.json").read_text())
    checked = json.loads((folder / "validation.json").read_text())
    cells = _cells(page)
    # Every mode's frequency and damping intervals, from model.json's numbers
    # (written by the model, not by the report), and its share per output.
    modes = model["modes"]["modes"]
    assert modes and len(_intervals(cells)) == 2 * len(modes)
    for m, shown in zip(modes, _intervals(cells)[::2], strict=True):
        _assert_shown(shown, m["frequency_interval_hz"])
    for m, shown in zip(modes, _intervals(cells)[1::2], strict=True):
        _assert_shown(shown, m["damping_interval"])
    for name in ("vel", "acc"):
        assert f"share in {name} (%)" in page
        share = model["modes"]["share_by_output"][name][0]
        assert f"{100 * share:.1f}" in cells
    # Each mode's shape over the outputs (real part and half width) and the
    # MAC matrix between the modes, as validation.json holds them.
    shapes = checked["validation"]["shapes"]
    assert "<h2>Mode shapes</h2>" in page
    assert len(shapes["modes"]) == len(modes)
    first = shapes["modes"][0]
    assert any(c.startswith(f"{first['shape_real'][0]:+.3f} +- ") for c in cells)
    assert f"{shapes['auto_mac'][0][1]:.3f}" in cells
    # Each output's fit on both parts and the joint fit.
    for part in ("estimation", "validation"):
        for name, v in checked[part]["outputs"].items():
            assert f"{v['fit_percent']:.2f}" in cells, (part, name)
        assert f"{checked[part]['joint_fit_percent']:.2f}" in cells
    # The stabilisation diagram over orders 2-10 around na = 8, and each
    # output's validation figures, embedded and written beside it.
    assert "Stabilisation diagram" in page and "na = 2, 4, 6, 8, 10" in page
    assert page.count("data:image/png;base64,") == 1 + 2 * 4
    for name in ("vel", "acc"):
        for kind in ("time", "spectrum", "residuals", "pole_zero"):
            assert (folder / f"validation_{name}_{kind}.png").stat().st_size > 0
    assert (folder / "stabilisation.png").exists()
    timings = json.loads((folder / "timings.json").read_text())
    assert "stabilisation" in timings


def test_an_option_a_shared_model_does_not_take_is_refused(tmp_path):
    rec = paper_experiment().run(FlexibleManipulator(), rng=0)
    np.savez(tmp_path / "rig.npz", u=rec.u, vel=rec.hub_velocity,
             acc=rec.end_acceleration, ts=rec.ts)  # fmt: skip
    out = run("identify", "rig.npz", "--output", "vel,acc", "--method", "sda",
              "--out", "m", cwd=tmp_path)  # fmt: skip
    assert out.returncode == 2 and len(out.stderr.splitlines()) == 1
    assert "takes one output" in out.stderr
    assert not (tmp_path / "m").exists()


def test_validate_reads_a_model_of_several_outputs_back(made):
    """`spiralid validate` on the shared model's file validates every output
    and gives the joint fit identify reported on the same validation part;
    a record without one of the model's outputs is refused by name."""
    _, folder = made
    cwd = folder.parent
    proc = run("validate", "m/model.json", "rig.npz", "--fraction",
               "0.6666666666666666", "--out", "v", cwd=cwd)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    again = json.loads((cwd / "v" / "validation.json").read_text())
    saved = json.loads((folder / "validation.json").read_text())["validation"]
    assert again["joint_fit_percent"] == pytest.approx(
        saved["joint_fit_percent"], rel=1e-12
    )
    for name in ("vel", "acc"):
        assert again["outputs"][name]["fit_percent"] == pytest.approx(
            saved["outputs"][name]["fit_percent"], rel=1e-12
        )
        assert (cwd / "v" / f"{name}_time.png").is_file()
    assert "joint fit %" in proc.stdout
    data = dict(np.load(cwd / "rig.npz"))
    del data["acc"]
    np.savez(cwd / "one.npz", **data)
    proc = run("validate", "m/model.json", "one.npz", cwd=cwd)
    assert proc.returncode == 2
    assert "outputs 'vel', 'acc'" in proc.stderr and "no variable 'acc'" in proc.stderr
