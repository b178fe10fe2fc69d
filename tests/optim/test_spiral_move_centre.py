"""SpiralSearch.move_centre: a point found outside the spiral moves."""

import numpy as np
import pytest

from spiralid.optim import SpiralSearch


def _sphere(x):
    return np.sum(np.atleast_2d(x) ** 2, axis=1)


def test_a_better_point_becomes_the_centre_and_the_search_rotates_about_it():
    search = SpiralSearch(_sphere, [(-5, 5)] * 2, "sda", rng=0, vectorized=True)
    assert search.move_centre([0.0, 0.0], 0.0)
    assert search.fun == 0.0 and np.array_equal(search.x, [0.0, 0.0])
    assert search.history[-1] == 0.0
    search.step()
    assert np.array_equal(search.x, [0.0, 0.0])  # nothing beats the optimum


def test_a_worse_point_is_refused():
    search = SpiralSearch(_sphere, [(-5, 5)] * 2, "sda", rng=0, vectorized=True)
    before = search.x
    assert not search.move_centre([4.0, 4.0], 32.0)
    assert np.array_equal(search.x, before)


def test_outside_the_bounds_is_an_error():
    search = SpiralSearch(_sphere, [(-5, 5)] * 2, "sda", rng=0, vectorized=True)
    with pytest.raises(ValueError, match="`x`"):
        search.move_centre([6.0, 0.0], 0.0)
