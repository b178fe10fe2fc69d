"""IOData: construction, split, detrend, loaders and bad input."""

from importlib import resources
from pathlib import Path

import numpy as np
import pytest
from scipy.io import savemat

from spiralid import datasets
from spiralid.sysid import IOData

# The shipped copy of the DaISy robot arm record (spiralid/datasets/).
ARM = Path(str(resources.files("spiralid.datasets") / "daisy_robot_arm.csv"))


def test_accepts_lists_and_column_vectors():
    d = IOData([1, 2, 3], np.array([[4.0], [5.0], [6.0]]), ts=0.5)
    assert d.u.dtype == float and d.u.shape == (3,) and d.y.shape == (3,)
    assert d.n == len(d) == 3
    np.testing.assert_array_equal(d.t, [0.0, 0.5, 1.0])


def test_split_is_contiguous_two_thirds():
    u = np.arange(9.0)
    d = IOData(u, -u, ts=1.0, input_name="torque", output_name="acc")
    est, val = d.split()
    np.testing.assert_array_equal(est.u, u[:6])
    np.testing.assert_array_equal(val.y, -u[6:])
    assert est.input_name == "torque" and val.output_name == "acc" and val.ts == 1.0


def test_detrend_remembers_offsets():
    d = IOData([1.0, 2.0, 3.0], [10.0, 12.0, 14.0], ts=1.0).detrend()
    np.testing.assert_allclose(d.u, [-1.0, 0.0, 1.0])
    assert d.u_offset == 2.0 and d.y_offset == 12.0
    np.testing.assert_allclose(d.y + d.y_offset, [10.0, 12.0, 14.0])


def test_csv_by_name_and_index(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("t,u,y\n0,1.5,2\n1,-1,3e-1\n2,0,4\n")
    d = IOData.from_csv(p, input="u", output="y", ts=0.1)
    np.testing.assert_array_equal(d.u, [1.5, -1.0, 0.0])
    np.testing.assert_array_equal(d.y, [2.0, 0.3, 4.0])
    assert d.input_name == "u"
    d2 = IOData.from_csv(p, input=1, output=2, ts=0.1)
    np.testing.assert_array_equal(d2.y, d.y)
    q = tmp_path / "nohead.csv"
    q.write_text("1,2\n3,4\n")
    d3 = IOData.from_csv(q, input=0, output=1, ts=1.0)
    np.testing.assert_array_equal(d3.u, [1.0, 3.0])


def test_npz_and_mat(tmp_path):
    u, y = np.linspace(0, 1, 5), np.linspace(1, 2, 5)
    np.savez(tmp_path / "r.npz", u=u, y=y, ts=0.01)
    d = IOData.from_npz(tmp_path / "r.npz")
    np.testing.assert_array_equal(d.y, y)
    assert d.ts == 0.01
    savemat(tmp_path / "r.mat", {"torque": u[:, None], "acc": y[None, :]})
    m = IOData.from_mat(tmp_path / "r.mat", input="torque", output="acc", ts=0.2)
    np.testing.assert_array_equal(m.u, u)
    np.testing.assert_array_equal(m.y, y)


def test_real_arm_loads():
    d = IOData.from_csv(ARM, input="u", output="y", ts=0.01)
    assert d.n == 1024
    np.testing.assert_allclose(d.u[:2], [0.22183165, 0.039027807])
    shipped = datasets.robot_arm()
    np.testing.assert_array_equal(shipped.u, d.u)
    np.testing.assert_array_equal(shipped.y, d.y)
    assert shipped.ts == 0.01 and datasets.robot_arm(ts=0.1).ts == 0.1


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_nonfinite_names_first_bad_sample(bad):
    y = np.ones(10)
    y[7] = bad
    y[8] = np.nan
    with pytest.raises(ValueError, match=r"`y` must be finite; got .* at sample 7"):
        IOData(np.ones(10), y, ts=1.0)


def test_bad_inputs():
    with pytest.raises(
        ValueError, match="`u` and `y` must have the same length; got 3 and 2"
    ):
        IOData([1, 2, 3], [1, 2], ts=1.0)
    with pytest.raises(
        ValueError, match=r"`u` must be a 1-D signal .* got shape \(2, 2, 2\)"
    ):
        # (N, m) is a record of m inputs; three axes are no signal.
        IOData(np.ones((2, 2, 2)), [1, 2], ts=1.0)
    with pytest.raises(ValueError, match="`ts` must be a finite number > 0"):
        IOData([1, 2], [1, 2], ts=0.0)
    with pytest.raises(ValueError, match="`u` must be a numeric 1-D signal"):
        IOData(["a", "b"], [1, 2], ts=1.0)
    d = IOData([1, 2, 3], [1, 2, 3], ts=1.0)
    with pytest.raises(ValueError, match=r"`fraction` must be in \(0, 1\); got 1.5"):
        d.split(1.5)
    with pytest.raises(ValueError, match="`fraction` leaves an empty part"):
        d.split(0.01)


def test_csv_bad_columns(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("u,y\n1,2\n3,oops\n")
    with pytest.raises(
        ValueError,
        match=r"column 'y' of '.*r.csv' must be numeric; got 'oops' on line 3",
    ):
        IOData.from_csv(p, ts=1.0)
    with pytest.raises(
        ValueError, match=r"`output` must be one of the columns \['u', 'y'\]"
    ):
        IOData.from_csv(p, output="acc", ts=1.0)
    with pytest.raises(
        ValueError, match=r"`input` column index must be in \[0, 1\]; got 5"
    ):
        IOData.from_csv(p, input=5, ts=1.0)


def test_npz_missing_variable_and_ts(tmp_path):
    np.savez(tmp_path / "r.npz", u=np.ones(3), y=np.ones(3))
    with pytest.raises(
        ValueError, match=r"`output` must be one of the variables \['u', 'y'\]"
    ):
        IOData.from_npz(tmp_path / "r.npz", output="acc")
    with pytest.raises(ValueError, match="`ts` must be given"):
        IOData.from_npz(tmp_path / "r.npz")
    np.savez(tmp_path / "s.npz", u=np.array(["a", "b"]), y=np.ones(2), ts=1.0)
    with pytest.raises(ValueError, match="`input` variable 'u' must be numeric"):
        IOData.from_npz(tmp_path / "s.npz")


def test_csv_needs_ts(tmp_path):
    p = tmp_path / "r.csv"
    p.write_text("u,y\n1,2\n3,4\n")
    with pytest.raises(
        ValueError, match=r"`ts` is required for .*a CSV file carries no sample time"
    ):
        IOData.from_csv(p)


def test_signals_are_private_read_only_copies():
    u, y = np.arange(5.0), np.ones(5)
    d = IOData(u, y, ts=1.0)
    assert u.flags.writeable and y.flags.writeable  # the caller's arrays untouched
    u[0] = 99.0
    assert d.u[0] == 0.0
    with pytest.raises(ValueError, match="read-only"):
        d.u[0] = 1.0


def test_csv_saved_by_excel_with_a_byte_order_mark(tmp_path):
    p = tmp_path / "excel.csv"
    p.write_bytes("u,y\n1,2\n3,4\n".encode("utf-8-sig"))
    d = IOData.from_csv(p, input="u", output="y", ts=1.0)
    np.testing.assert_array_equal(d.u, [1, 3])
    assert d.input_name == "u"


def test_csv_header_units_go_to_the_record(tmp_path):
    p = tmp_path / "rig.csv"
    p.write_text("torque [N m],accel (m/s^2)\n1,2\n3,4\n")
    d = IOData.from_csv(p, input="torque", output="accel (m/s^2)", ts=1.0)
    assert (d.input_name, d.input_unit) == ("torque", "N m")
    assert (d.output_name, d.output_unit) == ("accel", "m/s^2")
    assert d.output_label == "accel (m/s^2)"
    assert d.detrend().split(0.5)[1].input_unit == "N m"


@pytest.mark.parametrize("scale", [1e300, 1e-300])
def test_values_that_overflow_or_vanish_when_squared_are_refused(scale):
    u = np.arange(10.0) + 1
    with pytest.raises(ValueError, match="`y` must be rescaled"):
        IOData(u, u * scale, ts=1.0)


def test_non_utf8_csv_is_refused_clearly(tmp_path):
    p = tmp_path / "r.csv"
    p.write_bytes(b"\xff\xfe\x00\x01" * 10)
    with pytest.raises(ValueError, match="is not a text CSV file"):
        IOData.from_csv(p, ts=1.0)
    # Text in another encoding: which byte, and how to convert it.
    p.write_bytes("u,y\n1,2\n3,4 \u00b0\n".encode("latin-1"))
    with pytest.raises(ValueError, match="not UTF-8 text \\(byte 0xb0 on line 3"):
        IOData.from_csv(p, ts=1.0)
    p.write_bytes("u,y\n1,2\n".encode("utf-16"))
    with pytest.raises(ValueError, match="is UTF-16 text, not UTF-8"):
        IOData.from_csv(p, ts=1.0)


def test_cascaded_tanks_records_are_the_benchmarks():
    """Both records as the benchmark describes them: 1,024 samples at 4 s, a
    pump voltage in 0-10 V, and a level that saturates at 10 V (the
    overflow) in each record."""
    from spiralid.datasets import cascaded_tanks, load

    est, test = cascaded_tanks(), cascaded_tanks("test")
    for record in (est, test):
        assert (record.n, record.ts) == (1024, 4.0)
        assert (record.input_unit, record.output_unit) == ("V", "V")
        assert 0.0 <= record.u.min() and record.u.max() <= 10.0
        assert np.sum(record.y >= 10.0 - 1e-9) >= 1
    assert not np.array_equal(est.u, test.u)
    np.testing.assert_array_equal(load("cascaded_tanks_test").y, test.y)
    with pytest.raises(ValueError, match="record"):
        cascaded_tanks("validation")
