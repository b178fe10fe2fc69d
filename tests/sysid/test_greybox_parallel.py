"""A grey-box fit's simulations on several processes give the fit of one
process bit for bit (same search, same polish, same count of simulations),
on a process pool, a caller's executor and a Dask client; what cannot be
sent to another process is refused in one line."""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import spiralid as sid
from spiralid.sysid import GreyBox, Parameter

TS = 0.1


def spring_f(t, x, u, p):
    k, c = p
    return np.array([x[1], u[0] - k * x[0] - c * x[1] - 0.5 * x[0] ** 3])


def spring_g(x, u, p):
    return x[0]


def structure(**kw):
    params = [
        Parameter("k", 2.0, (0.5, 10.0), "N/m"),
        Parameter("c", 0.5, (0.05, 5.0), "N s/m"),
    ]
    return GreyBox(params, f=spring_f, g=spring_g, n_states=2, substeps=2, **kw)


@pytest.fixture(scope="module")
def record():
    rng = np.random.default_rng(3)
    u = np.repeat(rng.standard_normal(20), 10)
    y = structure().simulate([4.0, 0.8], u, TS)
    return sid.IOData(u, y + 0.01 * rng.standard_normal(y.size), ts=TS)


def fit(record, workers, method="spiral"):
    kw = dict(max_nfev=60, polish_nfev=20) if method == "spiral" else dict(max_nfev=60)
    return sid.identify(record, structure(), method, rng=5, workers=workers, **kw)


@pytest.fixture(scope="module")
def serial(record):
    return {m: fit(record, None, m) for m in ("spiral", "sda")}


@pytest.mark.parametrize("method", ["spiral", "sda"])
def test_a_process_pool_gives_the_serial_fit_bit_for_bit(record, serial, method):
    model = fit(record, 2, method)
    np.testing.assert_array_equal(model.params, serial[method].params)
    assert model.cost == serial[method].cost
    assert model.nfev == serial[method].nfev


def test_a_callers_executor_is_used_and_left_open(record, serial):
    with ThreadPoolExecutor(max_workers=2) as pool:
        model = fit(record, pool)
        assert pool.submit(int, "7").result() == 7  # still open
    np.testing.assert_array_equal(model.params, serial["spiral"].params)


def test_a_dask_client_gives_the_serial_fit(record, serial):
    distributed = pytest.importorskip("distributed")
    with distributed.Client(processes=False, n_workers=2, threads_per_worker=1) as c:
        model = fit(record, c)
    np.testing.assert_array_equal(model.params, serial["spiral"].params)


def test_what_cannot_be_sent_is_refused_in_one_line(record):
    params = [Parameter("k", 2.0, (0.5, 10.0))]
    box = GreyBox(params, f=lambda t, x, u, p: -p[0] * x + u, g=spring_g, n_states=1)
    with pytest.raises(ValueError, match=r"`workers`.*top level") as err:
        sid.identify(record, box, "oe", workers=2)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize(
    "workers, error, match",
    [("two", TypeError, "`workers` must be None, an int"), (0, ValueError, ">= 1")],
)
def test_bad_workers_are_refused(record, workers, error, match):
    with pytest.raises(error, match=match):
        fit(record, workers, "sda")
