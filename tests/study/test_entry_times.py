"""Figure 6a's time axis: one wall time per entry of a search's history,
also when a restart adds an entry between two callbacks."""

import types

import numpy as np

from spiralid.study.tasks import _entry_times


def test_a_restart_s_entry_takes_the_time_of_the_callback_that_covers_it():
    model = types.SimpleNamespace(history=np.zeros(6))
    # Callbacks saw 2, 3, 5 (a restart added one) and 6 entries.
    stamps = [(2, 11.0), (3, 12.0), (5, 14.0), (6, 15.0)]
    times = _entry_times(model, stamps, start=10.0)
    np.testing.assert_array_equal(times, [0.0, 1.0, 2.0, 4.0, 4.0, 5.0])
    assert np.all(np.diff(times) >= 0) and times.size == model.history.size


def test_a_callback_blind_to_the_history_stamps_one_entry_per_call():
    model = types.SimpleNamespace(history=np.zeros(3))
    times = _entry_times(model, [(None, 11.0), (None, 12.5)], start=10.0)
    np.testing.assert_array_equal(times, [0.0, 1.0, 2.5])
