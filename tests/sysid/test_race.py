"""The race between output error's starts: a polish that cannot reach the
lowest error another start reached, at its own pace, is given up, and the
kept model is the one the full polishes would keep."""

import numpy as np
import pytest

from spiralid.sysid import ARX, identify
from spiralid.sysid.estimation.linear.levenberg import STOPS, levenberg_marquardt


def _floored_cube():
    # |r|^2 = x^6 + 0.25: LM converges linearly (x -> 2x/3) onto a floor of
    # 0.25 that no step can pass.
    return (
        lambda x: np.array([x[0] ** 3, 0.5]),
        lambda x: np.array([[3.0 * x[0] ** 2], [0.0]]),
    )


def _polish(rival):
    residual, jacobian = _floored_cube()
    return levenberg_marquardt(
        residual,
        jacobian,
        np.array([1.0]),
        max_nfev=1000,
        stall=(20, 1e-6),
        rival=rival,
    )


def test_a_polish_that_cannot_reach_the_rival_is_given_up():
    alone = _polish(None)
    raced = _polish(0.2)
    assert raced.stop == 6 and raced.message == STOPS[6] and not raced.success
    assert raced.nfev < alone.nfev
    # Given up above the rival, whose cost it could never have reached.
    assert 2.0 * raced.cost > 0.2 and 2.0 * alone.cost > 0.2


@pytest.mark.parametrize("rival", [0.3, 0.2501])
def test_a_rival_within_reach_changes_nothing(rival):
    alone, raced = _polish(None), _polish(rival)
    assert raced.stop == alone.stop != 6
    assert raced.nfev == alone.nfev
    np.testing.assert_array_equal(raced.x, alone.x)


@pytest.mark.slow
def test_output_error_at_arx32_gives_up_the_crawling_start():
    # On the paper's record the polish from Steiglitz-McBride crawls along
    # the margin for its whole cap (6,500 evaluations) to a cost above the
    # least-squares start's; racing, it is given up, and the kept model is
    # the least-squares start's polish.
    from spiralid.reproduction import default_data

    est, _ = default_data().split(2 / 3)
    result = identify(est, ARX(32, 32, 0), method="oe").result
    runs = result.runs
    ls, sm = runs["ls"][1], runs["steiglitz-mcbride"][1]
    assert sm.stop == 6 and sm.nfev < 6500
    assert ls.stop != 6
    assert result.starts["ls"] < result.starts["steiglitz-mcbride"]
