"""Records of several outputs (issue 30, step 1): IOData with y of shape
(N, p), its readers, the rig's recording, and one-line refusals from the
functions that model one output."""

import numpy as np
import pytest

from spiralid.fms import FlexibleManipulator, bang_bang
from spiralid.sysid import ARX, IOData, PaperCost, identify, validate


def _two(n=50):
    rng = np.random.default_rng(0)
    u = rng.standard_normal(n)
    y = np.column_stack([rng.standard_normal(n) + 3.0, rng.standard_normal(n) - 1.0])
    return IOData(u, y, ts=0.1, output_name=("a", "b"), output_unit=("m", "rad"))


def test_several_outputs_keep_each_name_unit_and_offset():
    d = _two()
    assert d.n_outputs == 2 and d.y.shape == (50, 2)
    assert d.output_names == ("a", "b") and d.output_units == ("m", "rad")
    assert d.output_label == "a (m), b (rad)"
    flat = d.detrend()
    # Each output's own mean, by hand.
    np.testing.assert_allclose(flat.y_offsets, d.y.mean(axis=0))
    np.testing.assert_allclose(flat.y.mean(axis=0), 0.0, atol=1e-12)
    b = flat.output("b")
    assert (b.n_outputs, b.output_name, b.output_unit) == (1, "b", "rad")
    assert b.y_offset == pytest.approx(d.y[:, 1].mean())
    np.testing.assert_array_equal(flat.output(1).y, flat.y[:, 1])
    est, val = d.split(0.6)
    assert est.y.shape == (30, 2) and val.output_names == ("a", "b")


def test_one_output_stays_the_simple_case():
    d = IOData([0.0, 1.0, 2.0], [[1.0], [2.0], [3.0]], ts=1.0)
    assert d.y.shape == (3,) and d.n_outputs == 1 and d.output_names == ("y",)
    assert d.output("y") is d and d.outputs.shape == (3, 1)


def test_default_names_are_numbered_and_bad_ones_refused():
    y = np.ones((4, 3))
    assert IOData(np.ones(4), y, ts=1.0).output_names == ("y1", "y2", "y3")
    with pytest.raises(
        ValueError, match="`output_name` must have one entry per output"
    ):
        IOData(np.ones(4), y, ts=1.0, output_name=("a", "b"))
    with pytest.raises(ValueError, match="`output_name` must name each output once"):
        IOData(np.ones(4), y, ts=1.0, output_name=("a", "a", "b"))
    y[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"`y\[:, 1\]` must be finite.*sample 2"):
        IOData(np.ones(4), y, ts=1.0)
    with pytest.raises(ValueError, match=r"`which` must be one of \(.a., .b.\)"):
        _two().output("c")


def test_csv_and_npz_read_several_outputs(tmp_path):
    path = tmp_path / "r.csv"
    path.write_text("u [N m],a [m],b [rad]\n1,2,3\n4,5,6\n7,8,9\n")
    d = IOData.from_csv(path, input="u", output=["a", "b"], ts=0.1)
    assert d.output_names == ("a", "b") and d.output_units == ("m", "rad")
    np.testing.assert_array_equal(d.y, [[2, 3], [5, 6], [8, 9]])
    one = IOData.from_csv(path, input="u", output=["b"], ts=0.1)
    assert one.y.shape == (3,) and one.output_name == "b"
    with pytest.raises(ValueError, match="`output` must name each column once"):
        IOData.from_csv(path, input="u", output=["a", "a"], ts=0.1)
    np.savez(tmp_path / "r.npz", u=[1.0, 2, 3], a=[1.0, 2, 3], b=[3.0, 2, 1], ts=0.1)
    d = IOData.from_npz(tmp_path / "r.npz", output=["a", "b"])
    np.testing.assert_array_equal(d.y[:, 1], [3, 2, 1])


def test_the_rig_records_every_sensor_at_once():
    rec = FlexibleManipulator().simulate(bang_bang(0.3, 0.05, 0.1, 1.0, 500.0))
    d = rec.iodata(["hub_angle", "end_acceleration"])
    assert d.output_units == ("rad", "m/s^2")
    np.testing.assert_array_equal(d.y[:, 1], rec.end_acceleration)
    np.testing.assert_array_equal(d.output("hub_angle").y, rec.iodata("hub_angle").y)
    with pytest.raises(ValueError, match="`name` must list each output once"):
        rec.iodata(["hub_angle", "hub_angle"])


def test_single_output_functions_refuse_several_in_one_line():
    d = _two()
    with pytest.raises(ValueError, match=r"has 2 outputs \('a', 'b'\).*data.output"):
        PaperCost(ARX(1, 1, 0), d)
    # identify takes several outputs by its default method alone (one shared
    # denominator, tests/sysid/test_shared.py).
    with pytest.raises(ValueError, match="`method` 'sda' takes one output"):
        identify(d, ARX(1, 1, 0), method="sda")
    model = identify(d.output("a"), ARX(1, 1, 0), method="ls")
    with pytest.raises(ValueError, match=r"validate .* takes one"):
        validate(model, d)
