"""The grey box's default search (``"spiral"``'s, with its restarts) on a
lightly damped oscillator struck once: one generator gives one search,
every point it simulates lies in the parameters' bounds, the initial
values are simulated first, and once the
first poll's steps are below a hundredth of the box it draws points anew
where the poll alone would stay around its centre."""

import numpy as np
from scipy import signal

import spiralid as sid
from spiralid.sysid import GreyBox, Parameter
from spiralid.sysid.estimation.greybox.fit import _RESTARTS, _search
from spiralid.sysid.estimation.greybox.parallel import ParallelEvaluator
from spiralid.sysid.estimation.greybox.problem import GreyBoxProblem

TS = 0.05


def oscillator(p):
    k, c = p
    return [[0.0, 1.0], [-k, -c]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]]


class Recorded(GreyBoxProblem):
    """The problem, keeping every point it is asked to simulate."""

    def __call__(self, z):
        self.asked.append(np.array(z, dtype=float))
        return super().__call__(z)


def problem() -> Recorded:
    u = np.zeros(300)
    u[0] = 1.0 / TS  # a unit impulse, held one sample
    a, b, c, d = (np.asarray(m, dtype=float) for m in oscillator((4.0, 0.02)))
    _, y, _ = signal.dlsim(signal.cont2discrete((a, b, c, d), TS, "zoh"), u)
    box = GreyBox(
        [
            Parameter("k", 2.0, (0.5, 20.0), "N/m"),
            Parameter("c", 0.1, (0.001, 1.0), "N s/m"),
        ],
        ss=oscillator,
    )
    out = Recorded(sid.IOData(u, y.ravel(), ts=TS), box)
    out.asked = []
    return out


def search(seed: int, restarts=_RESTARTS) -> tuple[np.ndarray, np.ndarray]:
    """The search's result and the points it simulated, in the unit box."""
    p = problem()
    given = {"rng": np.random.default_rng(seed), "max_nfev": 200, "restarts": restarts}
    with ParallelEvaluator(p, None) as pool:
        z = _search(p, "spiral", given, pool)
    return z, np.array(p.asked)


def test_one_generator_gives_one_search_and_every_point_is_in_the_bounds():
    z, asked = search(5)
    z_again, asked_again = search(5)
    assert np.array_equal(z, z_again) and np.array_equal(asked, asked_again)
    assert np.all((asked >= 0.0) & (asked <= 1.0))
    # The initial values are simulated first (the first poll's population
    # holds them).
    np.testing.assert_array_equal(asked[0], problem().z0)
    assert np.all((z >= 0.0) & (z <= 1.0))
    # The last half of the budget: new runs over the box with the restarts,
    # the one poll's neighbourhood of its centre without.
    _, alone = search(5, restarts=False)
    spread = np.ptp(asked[len(asked) // 2 :], axis=0).max()
    spread_alone = np.ptp(alone[len(alone) // 2 :], axis=0).max()
    assert spread > 0.1 > spread_alone, (spread, spread_alone)
