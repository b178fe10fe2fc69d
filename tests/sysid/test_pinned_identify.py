"""The paper's configurations (and LS, OE, DE, LASDA, refine) keep their
results per seed: every theta and cost is compared with the values recorded
in data/pinned_identify.json, to a tolerance that holds on any processor.

Why a tolerance and short runs: these paths go through LAPACK, OpenBLAS and
NumPy's SIMD loops, whose last bits depend on the processor, and a
population search amplifies a last-bit difference at every iteration (at
1,500 evaluations Eb-SDA's cost differed by 3-10 % between OpenBLAS's
Haswell, Prescott and SandyBridge kernels). At 400 evaluations (20
iterations) and LASDA's 10 iterations the largest difference measured
between those kernels is 2e-9 in cost and 2e-8 in theta, against
tolerances of 1e-6 and 1e-5: two orders of magnitude of headroom, while any
change to a rule, the cost or a parametrisation moves them by far more. The
rule is written down in docs/design-notes.md ("Tests that hold on any
machine").

`python tests/sysid/test_pinned_identify.py` records the file from the
current code. Rerun it only for a change that is meant to move these
numbers, and say so in the commit; never to make this test pass.
"""

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.signal import lfilter

from spiralid.sysid import ARX, IOData, PaperCost, identify

PINS = Path(__file__).with_name("data") / "pinned_identify.json"


def record() -> IOData:
    """A small lightly damped record with output noise (two modes)."""
    rng = np.random.default_rng(2024)
    u = np.zeros(400)
    u[10:14], u[110:114], u[210:214], u[310:314] = 1.0, -1.0, 1.0, -1.0
    u += 0.05 * rng.standard_normal(400)
    a = np.real(
        np.poly(
            [
                0.97 * np.exp(0.3j),
                0.97 * np.exp(-0.3j),
                0.93 * np.exp(1.1j),
                0.93 * np.exp(-1.1j),
            ]
        )
    )
    y = lfilter([0.0, 0.4, 0.3, -0.1], a, u) + 0.02 * rng.standard_normal(400)
    return IOData(u, y, ts=0.002)


ARX44 = ARX(4, 4, 1)


def cases():
    """(name, identify keyword arguments): the paper's configurations as
    reproduce() runs them (budget, max_iter = 10 x budget, its gain), plus
    lasda, DE, refine, LS and OE."""
    est = record().split(2 / 3)[0]
    gain = PaperCost(ARX44, est, predictor="simulation").w
    rep = dict(n_points=20, max_nfev=400, max_iter=4000)
    out = []
    for seed in (0, 1):
        for method in ("sda", "ebsda"):
            for par in ("coefficients", "reflection"):
                out.append(
                    (
                        f"{method}-{par}-{seed}",
                        dict(
                            method=method,
                            parametrization=par,
                            rng=seed,
                            gain=gain,
                            **rep,
                        ),
                    )
                )
        out.append(
            (
                f"ebsda-refine-{seed}",
                dict(method="ebsda", refine=True, rng=seed, gain=gain, **rep),
            )
        )
        out.append(
            (
                f"ebsda-gain0.1-{seed}",
                dict(method="ebsda", rng=seed, gain=0.1 * gain, **rep),
            )
        )
        out.append((f"de-{seed}", dict(method="de", rng=seed, gain=gain, **rep)))
        out.append(
            (
                f"de-reflection-{seed}",
                dict(
                    method="de",
                    parametrization="reflection",
                    rng=seed,
                    gain=gain,
                    **rep,
                ),
            )
        )
    out.append(("lasda-0", dict(method="lasda", rng=0, n_points=10, max_iter=10)))
    out.append(
        (
            "sda-onestep-0",
            dict(method="sda", predictor="one-step", rng=0, n_points=10, max_iter=40),
        )
    )
    out.append(
        (
            "ebsda-measured-0",
            dict(
                method="ebsda",
                initial="measured",
                rng=0,
                n_points=10,
                max_iter=40,
                refine=True,
            ),
        )
    )
    out.append(("ls", dict(method="ls")))
    out.append(("oe", dict(method="oe")))
    out.append(("oe-measured", dict(method="oe", initial="measured")))
    return est, out


def run(est, kwargs):
    model = identify(est, ARX44, **kwargs)
    return {
        "theta": [float(v).hex() for v in model.theta],
        "cost": float(model.cost).hex(),
    }


# Relative tolerances: see the module docstring for the headroom measured.
COST_RTOL = 1e-6
THETA_TOL = 1e-5


def assert_close_to_pin(got: dict, pinned: dict) -> None:
    theta = np.array([float.fromhex(v) for v in got["theta"]])
    want = np.array([float.fromhex(v) for v in pinned["theta"]])
    assert theta.shape == want.shape
    assert np.all(np.abs(theta - want) <= THETA_TOL * (1 + np.abs(want))), (
        theta,
        want,
    )
    cost, want_cost = float.fromhex(got["cost"]), float.fromhex(pinned["cost"])
    assert cost == pytest.approx(want_cost, rel=COST_RTOL)


EST, CASES = cases()
PINNED = json.loads(PINS.read_text())


def test_every_case_is_pinned():
    assert sorted(PINNED) == sorted(name for name, _ in CASES)


@pytest.mark.parametrize(("name", "kwargs"), CASES, ids=[n for n, _ in CASES])
def test_same_theta_and_cost_as_recorded(name, kwargs):
    assert_close_to_pin(run(EST, kwargs), PINNED[name])


BUDGETED = [(n, kw) for n, kw in CASES if "max_nfev" in kw]


@pytest.mark.parametrize(("name", "kwargs"), BUDGETED, ids=[n for n, _ in BUDGETED])
def test_the_budget_rule_gives_the_same_runs(name, kwargs):
    # reproduce() used to pass max_iter = 10 x max_nfev; the one budget rule
    # (max_iter = max_nfev when only a budget is given) stops them alike. Both
    # runs are made here, on one machine, so they must agree bit for bit.
    without = {k: v for k, v in kwargs.items() if k != "max_iter"}
    assert run(EST, without) == run(EST, kwargs)


if __name__ == "__main__":
    est, todo = cases()
    PINS.write_text(json.dumps({name: run(est, kw) for name, kw in todo}, indent=1))
