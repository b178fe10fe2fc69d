"""The SQLite result store: atomic rows, one writer, one specification."""

import sqlite3

import pytest

from spiralid.study import ResultStore, StoreLockedError

ROW = {
    "key": "k1",
    "data": "rig",
    "predictor": "one-step",
    "parametrization": "reflection",
    "label": "SDA",
    "method": "sda",
    "seed": 3,
    "cost": 12.5,
    "fit_val": 80.25,
    "nfev": 500,
    "seconds": 0.5,
    "stable": True,
    "model": {"theta": [0.1, 0.2], "history": [20.0, 12.5]},
}


def test_rows_round_trip_and_persist(tmp_path):
    path = tmp_path / "s.sqlite"
    with ResultStore.open(path, "d1", "spec text") as db:
        db.add(ROW)
        assert db.keys() == {"k1"} and len(db) == 1
    with ResultStore.open(path, readonly=True) as db:
        assert db.rows() == [ROW]
        assert db.meta() == {"digest": "d1", "spec": "spec text"}
    # Committed: visible to plain sqlite3 too.
    assert sqlite3.connect(path).execute("select cost from runs").fetchone() == (12.5,)


def test_a_second_writer_is_refused(tmp_path):
    path = tmp_path / "s.sqlite"
    with ResultStore.open(path, "d1"):
        with pytest.raises(StoreLockedError, match="in use by another study \\(pid"):
            ResultStore.open(path, "d1")
    # Released on close: a later study may write.
    ResultStore.open(path, "d1").close()


def test_another_specification_is_refused(tmp_path):
    path = tmp_path / "s.sqlite"
    ResultStore.open(path, "d1").close()
    with pytest.raises(ValueError, match="another specification"):
        ResultStore.open(path, "d2")


def test_not_a_store(tmp_path):
    bad = tmp_path / "bad.sqlite"
    bad.write_text("hello, not a database " * 50)
    with pytest.raises(ValueError, match="not a spiralid store"):
        ResultStore.open(bad, "d1")
    with pytest.raises(ValueError, match="does not exist"):
        ResultStore.open(tmp_path / "none.sqlite", readonly=True)
