"""The grey box's initial state (given, or estimated as Parameters), its
compiled Runge-Kutta loop against the Python one and SciPy's exact
zero-order hold, and the bad input the family refuses or turns into the
search's penalty."""

import json
import math

import numba
import numpy as np
import pytest
from scipy import signal

import spiralid as sid
from spiralid.sysid import GreyBox, Parameter
from spiralid.sysid.estimation.greybox.problem import GreyBoxProblem

TRUE = np.array([4.0, 0.6, 1.5])  # k (N/m), c (N s/m), m (kg)
X0 = np.array([0.8, -0.5])  # position (m), velocity (m/s)
TS = 0.05


def msd(p):
    k, c, m = p
    return [[0.0, 1.0], [-k / m, -c / m]], [[0.0], [1.0 / m]], [[1.0, 0.0]], [[0.0]]


def msd_f(t, x, u, p):
    return np.array([x[1], (u[0] - p[0] * x[0] - p[1] * x[1]) / p[2]])


def msd_g(x, u, p):
    return x[0]


msd_f_jit = numba.njit(msd_f)
msd_g_jit = numba.njit(msd_g)


def parameters(values=(2.0, 1.0, 1.0)):
    return [
        Parameter("k", values[0], (0.1, 20.0), "N/m"),
        Parameter("c", values[1], (0.01, 10.0), "N s/m"),
        Parameter("m", values[2], (0.1, 10.0), "kg"),
    ]


def free_state():
    return [
        Parameter("x1_0", 0.0, (-2.0, 2.0), "m"),
        Parameter("x2_0", 0.0, (-2.0, 2.0), "m/s"),
    ]


def scipy_run(u, x0=X0):
    """The exact zero-order-hold response from `x0`, by SciPy."""
    a, b, c, d = (np.asarray(m, dtype=float) for m in msd(TRUE))
    sys_d = signal.cont2discrete((a, b, c, d), TS, "zoh")
    _, y, _ = signal.dlsim(sys_d, u, x0=x0)
    return y.ravel()


def record(n=400, noise=0.02, seed=3):
    rng = np.random.default_rng(seed)
    u = np.repeat(rng.standard_normal(n // 10), 10)
    y = scipy_run(u)
    return sid.IOData(u, y + noise * np.std(y) * rng.standard_normal(n), ts=TS)


# -- the initial state --------------------------------------------------------


def test_a_given_initial_state_is_scipys_response_from_it():
    rec = record(noise=0.0)
    for box in (
        GreyBox(parameters(TRUE), ss=msd, x0=X0),
        GreyBox(parameters(TRUE), f=msd_f, g=msd_g, n_states=2, x0=X0),
    ):
        y = box.simulate(TRUE, rec.u, TS)
        assert np.max(np.abs(y - rec.y)) < 1e-7 * np.max(np.abs(rec.y)), box.kind


def test_an_estimated_initial_state_is_recovered_within_its_interval():
    rec = record()
    box = GreyBox(parameters(), ss=msd, x0=free_state())
    assert box.names == ("k", "c", "m", "x1_0", "x2_0")
    np.testing.assert_array_equal(box.x0, [0.0, 0.0])
    model = sid.identify(rec, box, method="oe")
    truth = np.r_[TRUE, X0]
    # Five 95 % intervals miss one truth one time in four by chance: check
    # them at 99.9 % (3.29 standard deviations, 1.68 times as wide).
    low, high = model.intervals.T
    middle, half = (low + high) / 2, (high - low) / 2
    assert np.all(np.abs(truth - middle) < 1.68 * half), model.summary()
    np.testing.assert_allclose(model.values, truth, rtol=0.05, atol=0.02)
    assert "x1_0 = " in model.summary() and "m/s" in model.summary()
    # From rest instead, the same structure fits the same record worse.
    rest = sid.identify(rec, GreyBox(parameters(), ss=msd), method="oe")
    assert model.cost < rest.cost


def test_a_fixed_initial_state_entry_is_held_and_a_mixed_one_fits(tmp_path):
    rec = record()
    held = Parameter("x1_0", float(X0[0]), (-2.0, 2.0), "m", free=False)
    box = GreyBox(
        parameters(), f=msd_f_jit, g=msd_g_jit, n_states=2, x0=[held, free_state()[1]]
    )
    model = sid.identify(rec, box, method="oe", polish_nfev=60)
    assert model.values[3] == X0[0] and np.isnan(model.intervals[3]).all()
    assert abs(model.values[4] - X0[1]) < 0.05
    path = tmp_path / "model.json"
    path.write_text(json.dumps(model.to_dict()))
    back = sid.sysid.load_model(path)
    assert back.structure.names == box.names
    assert [p.free for p in back.structure.state_parameters] == [False, True]
    np.testing.assert_array_equal(back.simulate(rec), model.simulate(rec))


def test_simulate_takes_the_functions_parameters_alone():
    box = GreyBox(parameters(TRUE), ss=msd, x0=[Parameter("x1_0", 0.8, (-2, 2)), -0.5])
    u = np.ones(50)
    np.testing.assert_array_equal(
        box.simulate(TRUE, u, TS), box.simulate(np.r_[TRUE, 0.8], u, TS)
    )


# -- the compiled loop --------------------------------------------------------


def test_the_compiled_loop_is_the_python_loop_to_rounding():
    rec = record(noise=0.0)
    values = np.r_[TRUE, X0]
    py = GreyBox(parameters(), f=msd_f, g=msd_g, n_states=2, x0=free_state())
    nb = GreyBox(parameters(), f=msd_f_jit, g=msd_g_jit, n_states=2, x0=free_state())
    y_py, y_nb = py.simulate(values, rec.u, TS), nb.simulate(values, rec.u, TS)
    np.testing.assert_allclose(y_nb, y_py, rtol=1e-12, atol=1e-14)
    # and both are SciPy's exact hold within Runge-Kutta's error
    assert np.max(np.abs(y_nb - rec.y)) < 1e-7 * np.max(np.abs(rec.y))


def test_a_compiled_output_may_be_a_one_element_array():
    g_array = numba.njit(lambda x, u, p: np.array([x[0]]))
    u = np.ones(40)
    a = GreyBox(parameters(TRUE), f=msd_f_jit, g=g_array, n_states=2, x0=X0)
    b = GreyBox(parameters(TRUE), f=msd_f_jit, g=msd_g_jit, n_states=2, x0=X0)
    np.testing.assert_array_equal(a.simulate(TRUE, u, TS), b.simulate(TRUE, u, TS))


# -- bad input ------------------------------------------------------------------


def _f_text(t, x, u, p):
    return "dx"


def _f_nan(t, x, u, p):
    return np.array([x[1], np.nan])


@numba.njit
def _g_two_arguments(x, u):
    return x[0]


def _f_blows_up_at(p_high):
    """A Python f that divides by zero for a stiffness above `p_high`."""

    def f(t, x, u, p):
        if p[0] > p_high:
            return np.array([x[1], 1.0 / 0.0])
        return msd_f(t, x, u, p)

    return f


def _f_sqrt(t, x, u, p):
    # math.sqrt raises on a negative argument where numpy gives NaN.
    return np.array([x[1], (u[0] - p[0] * math.sqrt(x[0] + 0.1)) / p[2]])


BAD = [
    (lambda: GreyBox(parameters(), ss=msd, x0=[1.0]), ValueError, "`x0`"),
    (lambda: GreyBox(parameters(), ss=msd, x0=[1.0, "a"]), ValueError, "`x0`"),
    (
        lambda: GreyBox(parameters(), ss=msd, x0=[Parameter("k", 0, (-1, 1)), 0]),
        ValueError,
        "['k']",
    ),
    (lambda: Parameter("x1_0", 3.0, (-1.0, 1.0)), ValueError, "'x1_0'"),
    (lambda: Parameter("x1_0", 0.0, (1.0, -1.0)), ValueError, "'x1_0'"),
    (lambda: Parameter("x1_0", 0.0, (-np.inf, 1.0)), ValueError, "'x1_0'"),
    (lambda: GreyBox(parameters(), ss=msd, substeps=2.5), TypeError, "`substeps`"),
    (
        lambda: GreyBox(parameters(), f=msd_f, g=msd_g, n_states=0),
        ValueError,
        "`n_states`",
    ),
    (
        lambda: GreyBox(parameters(), f=msd_f, g=msd_g, n_states=2).simulate(
            [1.0], np.ones(5), TS
        ),
        ValueError,
        "`values`",
    ),
    (
        lambda: GreyBox(parameters(), f=_f_text, g=msd_g, n_states=2),
        ValueError,
        "`f` (_f_text)",
    ),
    (
        lambda: GreyBox(parameters(), f=msd_f, g=_g_two_arguments, n_states=2),
        TypeError,
        "`g` (_g_two_arguments)",
    ),
    (
        lambda: GreyBox(parameters(), f=_f_nan, g=msd_g, n_states=2),
        ValueError,
        "`f` (_f_nan) returned a non-finite",
    ),
    (
        lambda: GreyBox(parameters(), f=msd_f, g=msd_g, n_states=3),
        ValueError,
        "`f` (msd_f) must return dx/dt of shape (3,)",
    ),
]


@pytest.mark.parametrize("make, error, words", BAD)
def test_bad_input_is_refused_in_one_line(make, error, words):
    with pytest.raises(error) as refused:
        make()
    message = str(refused.value)
    assert "\n" not in message and words in message, message


def test_a_python_f_that_raises_mid_search_costs_the_penalty():
    rec = record(n=200)
    box = GreyBox(parameters(), f=_f_blows_up_at(10.0), g=msd_g, n_states=2)
    problem = GreyBoxProblem(rec, box)
    high = problem.to_box([15.0, 1.0, 1.0])
    assert problem(high) == problem.penalty
    assert problem(problem.z0) < problem.penalty
    # math.sqrt of a negative level: the run stops there, the search goes on
    box = GreyBox(parameters(), f=_f_sqrt, g=msd_g, n_states=2)
    y = box.simulate([1.0, 0.0, 1.0], -np.ones(400), TS)
    assert np.isfinite(y[0]) and np.isnan(y[-1])
    model = sid.identify(rec, box, method="ebsda", rng=0, max_nfev=60)
    assert np.isfinite(model.cost)


def test_every_search_keeps_to_the_bounds():
    rec = record(n=200)
    tight = [Parameter("k", 2.0, (1.0, 3.0)), *parameters()[1:]]
    for method in ("spiral", "sda"):
        model = sid.identify(
            rec, GreyBox(tight, ss=msd), method=method, rng=0, max_nfev=150
        )
        low, high = np.array([p.bounds for p in tight]).T
        assert np.all(low <= model.values) and np.all(model.values <= high)
