"""The Cascaded Tanks grey box (spiralid.datasets.tanks_model): its
equations against hand-worked values, its compiled run against its Python
original, and a fitted model's file read back through the functions'
import path."""

import json
import math

import numpy as np
import pytest

import spiralid as sid
from spiralid.datasets import cascaded_tanks, tanks_model
from spiralid.datasets.tanks_model import (
    NO_TOP,
    OVERFLOWS,
    SURPLUS_SHARE,
    TANKS_PARAMETERS,
    tanks_f,
    tanks_f_inflow,
    tanks_f_mixed,
    tanks_g,
    tanks_greybox,
)
from spiralid.sysid import GreyBox

#: upper_outflow, area_ratio, lower_outflow, pump_gain, overflow_share,
#: sensor_offset, pump_threshold, lower_top, upper_exponent, lower_exponent
P = np.array([0.04, 1.0, 0.05, 0.05, 0.5, 0.3, 0.6, 9.5, 0.5, 0.5])


def test_the_equations_by_hand():
    u = np.array([3.0])
    # Both tanks below their tops: Torricelli outflows, the pump above its
    # threshold.
    dx = tanks_f(0.0, np.array([4.0, 2.25]), u, P)
    q_up = 0.04 * 2.0
    np.testing.assert_allclose(
        dx, [0.05 * (3.0 - 0.6) - q_up, 1.0 * q_up - 0.05 * 1.5], rtol=1e-14
    )
    # Below the threshold the pump moves nothing.
    assert tanks_f(0.0, np.array([4.0, 2.25]), np.array([0.5]), P)[0] == -q_up
    # The upper tank at its top spills its surplus, half of it (the share)
    # into the lower tank.
    strong = np.array([5.0])
    full = tanks_f(0.0, np.array([10.0, 2.25]), strong, P)
    surplus = 0.05 * 4.4 - 0.04 * math.sqrt(10.0)
    assert surplus > 0
    np.testing.assert_allclose(
        full, [0.0, 0.04 * math.sqrt(10.0) - 0.05 * 1.5 + 0.5 * surplus]
    )
    # The lower tank at its top fills no further; it still drains.
    assert tanks_f(0.0, np.array([10.0, 9.5]), strong, P)[1] == 0.0
    assert tanks_f(0.0, np.array([0.0, 9.5]), strong, P)[1] < 0.0
    # The sensor: level plus offset, saturating at 10 V.
    assert tanks_g(np.array([0.0, 4.0]), u, P) == pytest.approx(4.3)
    assert tanks_g(np.array([0.0, 9.9]), u, P) == 10.0


def test_the_inflow_overflow_by_hand():
    strong = np.array([5.0])
    pump = 0.05 * (5.0 - 0.6)
    # Below the top both overflows are the same equations.
    below = np.array([4.0, 2.25])
    np.testing.assert_array_equal(
        tanks_f_inflow(0.0, below, strong, P), tanks_f(0.0, below, strong, P)
    )
    # At the top, half (the share) of the pump's whole inflow reaches the
    # lower tank, not half of the surplus.
    full = tanks_f_inflow(0.0, np.array([10.0, 2.25]), strong, P)
    np.testing.assert_allclose(
        full, [0.0, 0.04 * math.sqrt(10.0) - 0.05 * 1.5 + 0.5 * pump]
    )
    # A full upper tank that drains faster than the pump fills it spills
    # nothing, in either form.
    weak = np.array([0.7])
    np.testing.assert_array_equal(
        tanks_f_inflow(0.0, np.array([10.0, 2.25]), weak, P),
        tanks_f(0.0, np.array([10.0, 2.25]), weak, P),
    )


def test_the_mixed_overflow_by_hand():
    strong = np.array([5.0])
    pump = 0.05 * (5.0 - 0.6)
    q_up = 0.04 * math.sqrt(10.0)
    surplus = pump - q_up
    mixed = np.append(P, 0.3)  # surplus_share
    below = np.array([4.0, 2.25])
    np.testing.assert_array_equal(
        tanks_f_mixed(0.0, below, strong, mixed), tanks_f(0.0, below, strong, P)
    )
    # At the top: half the pump's inflow and 0.3 of the surplus.
    full = tanks_f_mixed(0.0, np.array([10.0, 2.25]), strong, mixed)
    np.testing.assert_allclose(
        full, [0.0, q_up - 0.05 * 1.5 + 0.5 * pump + 0.3 * surplus]
    )
    # With either share zero it is the other form.
    no_surplus = np.append(P, 0.0)
    np.testing.assert_allclose(
        tanks_f_mixed(0.0, np.array([10.0, 2.25]), strong, no_surplus),
        tanks_f_inflow(0.0, np.array([10.0, 2.25]), strong, P),
    )
    no_inflow = np.append(P, 0.5)
    no_inflow[4] = 0.0
    np.testing.assert_allclose(
        tanks_f_mixed(0.0, np.array([10.0, 2.25]), strong, no_inflow),
        tanks_f(0.0, np.array([10.0, 2.25]), strong, P),
    )


def test_the_mixed_overflow_balances_the_water():
    """Mass balance over a run that spills: what the pump put in equals
    the upper tank's rise plus what it sent on (its outflow and the whole
    spill), integrated independently of the model's own Runge-Kutta loop
    (SciPy's adaptive solver, with the spill's shares set to one so that
    every spilled drop reaches the lower tank)."""
    from scipy.integrate import solve_ivp

    p = np.append(P, 1.0)
    p[4] = 0.0  # only the surplus share, 1: the water is all conserved
    p[1] = 1.0  # the two levels in one unit of volume
    p[7] = 1e9  # no lower top
    u = np.array([6.0])

    def rates(t, z):
        x = z[:2]
        dx = tanks_f_mixed(t, x, u, p)
        return [dx[0], dx[1], p[2] * max(x[1], 0.0) ** 0.5]

    run = solve_ivp(
        rates, (0.0, 400.0), [9.0, 2.0, 0.0], max_step=0.5, rtol=1e-9, atol=1e-9
    )
    upper, lower, drained = run.y[:, -1]
    assert upper == pytest.approx(10.0, abs=1e-6)  # it reached its top
    pumped = 0.05 * (6.0 - 0.6) * 400.0
    assert (upper - 9.0) + (lower - 2.0) + drained == pytest.approx(pumped, rel=1e-5)


def test_the_steady_states_with_and_without_the_lower_top():
    """A long run at a constant input settles where the outflows balance
    the pump, by hand: ``x0 = (pump / k1)^2`` and ``x1 = (a pump / k2)^2``
    (9 V each here, the upper tank below its top); with the lower tank's
    top below that, at its top instead."""
    u = np.full((1000, 1), 3.0)
    pump = 0.05 * (3.0 - 0.6)
    x1 = (1.0 * pump / 0.04) ** 2
    assert x1 == pytest.approx(9.0)
    values = {"upper_outflow": 0.04, "lower_outflow": 0.04, "area_ratio": 1.0}
    values |= {"pump_gain": 0.05, "pump_threshold": 0.6, "sensor_offset": 0.3}
    for top, level in ((False, x1), (True, 8.0)):
        box = tanks_greybox(x0=[2.0, 1.0], lower_top=top)
        p = box.initial_values
        for name, value in values.items():
            p[box.names.index(name)] = value
        if top:
            p[box.names.index("lower_top")] = 8.0
        else:
            assert p[box.names.index("lower_top")] == NO_TOP
        y = box.simulate(p, u, 4.0)
        assert np.ravel(y)[-1] == pytest.approx(level + 0.3, abs=1e-3)


def test_the_builder_without_the_lower_top():
    box = tanks_greybox(lower_top=False)
    k = box.names.index("lower_top")
    assert not box.free[k] and box.free.sum() == 9
    assert box.initial_values[k] == NO_TOP
    with pytest.raises(TypeError, match="`lower_top`"):
        tanks_greybox(lower_top="no")


@pytest.mark.parametrize("overflow", list(OVERFLOWS))
def test_the_compiled_model_runs_as_its_python_original(overflow):
    est = cascaded_tanks()
    box = tanks_greybox(x0=[6.0, 5.0], overflow=overflow)
    # Every call interpreted: the shared body's original, not the Numba
    # wrapper's (which calls the compiled body).
    form = {"surplus": 0, "inflow": 1, "mixed": 2}[overflow]

    def python_f(t, x, u, p):
        return tanks_model._rates.py_func(x, u, p, form)

    python = GreyBox(
        box.parameters, f=python_f, g=tanks_g.py_func, n_states=2,
        x0=[6.0, 5.0], substeps=box.substeps,
    )  # fmt: skip
    values = box.initial_values
    values[3] = 0.2  # a strong pump: the upper tank reaches its top and spills
    y = box.simulate(values, est.u[:300], est.ts)
    np.testing.assert_allclose(
        y, python.simulate(values, est.u[:300], est.ts), rtol=1e-12, atol=1e-12
    )
    assert np.all(np.isfinite(y)) and np.max(y) <= 10.0


def test_the_builder_and_a_saved_fit(tmp_path):
    box = tanks_greybox()
    assert box.names[: len(TANKS_PARAMETERS)] == tuple(TANKS_PARAMETERS)
    assert box.names[-2:] == ("upper_level_0", "lower_level_0")
    assert box.free.sum() == 10 and tanks_greybox(exponents=True).free.all()
    with pytest.raises(ValueError, match="`x0`"):
        tanks_greybox(x0="rest")
    # The default is the first of the one table, the inflow form.
    assert box.functions["f"] is tanks_f_inflow is next(iter(OVERFLOWS.values()))
    assert tanks_greybox(overflow="surplus").functions["f"] is tanks_f
    assert set(OVERFLOWS) == {"surplus", "inflow", "mixed"}
    # Only the mixed form has the second share, after the table's.
    mixed = tanks_greybox(overflow="mixed")
    assert mixed.functions["f"] is tanks_f_mixed
    assert mixed.names[: len(TANKS_PARAMETERS) + 1] == (
        *TANKS_PARAMETERS,
        *SURPLUS_SHARE,
    )
    assert mixed.free.sum() == 11 and "surplus_share" not in box.names
    with pytest.raises(ValueError, match="`overflow`"):
        tanks_greybox(overflow="jet")
    with pytest.raises(TypeError, match="`overflow`"):
        tanks_greybox(overflow=["inflow"])
    est = cascaded_tanks()
    model = sid.identify(est, box, method="oe", polish_nfev=3)
    path = tmp_path / "model.json"
    path.write_text(json.dumps(model.to_dict()))
    text = path.read_text()
    assert "spiralid.datasets.tanks_model:tanks_f_inflow" in text
    back = sid.sysid.load_model(path)
    np.testing.assert_array_equal(back.simulate(est), model.simulate(est))
