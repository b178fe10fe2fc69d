"""What bounds a model of the nonlinear rig's hub angle (prints only).

The paper's experiment (:func:`spiralid.fms.paper_experiment`) on
:func:`spiralid.fms.nonlinear_rig` (hub friction with stiction, torque
saturation), hub angle, estimation on the first 2/3 and free-run validation
fit % on the last third. The linear model is the default method's
``ARX(8, 8, 0)`` with two integrators, the NARX goal's reference
(docs/results/narx.md). Printed, for one seed:

1. the linear model's fit;
2. the ceiling: the same rig simulated without sensor noise or encoder
   quantisation, against the measured record: what a perfect model of the
   rig's dynamics would score;
3. a bound for capturing stiction alone: the linear model's fit with its
   error set to zero wherever the true hub is stuck (velocity below
   0.02 rad/s for at least 10 samples);
4. the friction law where the physics puts it, at the torque input: the
   linear model driven by ``u - alpha tanh(beta v / s_v)`` (``v`` the
   model's own last increment, ``s_v`` the increments' standard
   deviation), ``alpha`` and ``beta`` chosen on a grid by the estimation
   fit, then every coefficient refitted by least squares of the free-run
   error (SciPy); and the same refit started from the friction-free rig's
   linear model with the rig's true friction level;
5. the NARX of the goal (``NARX(7, 8, 0, integrator=2)``) by output error
   with nothing held back, no weight decay and up to 200 rounds, and how
   many rounds Levenberg-Marquardt took.

Usage: ``python benchmarks/narx_limits.py [--seed 0]`` (a few minutes).
"""

from __future__ import annotations

import argparse
import os
import time

# One BLAS thread, as benchmarks/nonparametric.py: the fits are the same
# from run to run (a threaded BLAS sums in another order).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from numba import njit
from scipy.ndimage import binary_opening
from scipy.optimize import least_squares

from spiralid.fms import FlexibleManipulator, Sensors, nonlinear_rig, paper_experiment
from spiralid.sysid import ARX, NARX, identify
from spiralid.sysid.validation.fit import fit_percent


@njit(cache=True)
def _friction_at_input(a, b, alpha, beta, u, scale):
    """Free run of ``A y = B (u - alpha tanh(beta dy(t-1) / scale))``."""
    n = u.size
    y = np.zeros(n)
    w = np.zeros(n)
    for t in range(n):
        v = y[t - 1] - y[t - 2] if t >= 2 else 0.0
        w[t] = u[t] - alpha * np.tanh(beta * v / scale)
        s = 0.0
        for i in range(1, a.size):
            if t - i >= 0:
                s -= a[i] * y[t - i]
        for j in range(b.size):
            if t - j >= 0:
                s += b[j] * w[t - j]
        y[t] = s
    return y


def _refit(a, b, alpha, beta, u, y, scale):
    """Every coefficient of the friction-at-input model by least squares of
    the free-run error on ``y`` (the estimation part)."""
    na = a.size

    def residual(p):
        aa, bb = np.r_[1.0, p[: na - 1]], p[na - 1 : na - 1 + b.size]
        run = _friction_at_input(aa, bb, p[-2], np.exp(p[-1]), u[: y.size], scale)
        return (run - y) / scale

    p0 = np.r_[a[1:], b, alpha, np.log(beta)]
    with np.errstate(all="ignore"):
        p = least_squares(residual, p0, x_scale="jac", max_nfev=400).x
    return np.r_[1.0, p[: na - 1]], p[na - 1 : na - 1 + b.size], p[-2], np.exp(p[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    seed = ap.parse_args().seed
    t0 = time.perf_counter()
    exp, rig = paper_experiment(), nonlinear_rig()
    rec = exp.run(rig=rig, rng=seed)
    data = rec.iodata("hub_angle")
    est, val = data.split(2 / 3)
    ne = est.n

    def row(label: str, run: np.ndarray) -> None:
        e, v = fit_percent(est.y, run[:ne]), fit_percent(val.y, run[ne:])
        print(f"| {label} | {e:.2f} | {v:.2f} |", flush=True)

    arx = identify(est, ARX(8, 8, 0), integrator=2, rng=seed)
    linear = arx.simulate(data.u)
    print(f"# Hub angle of the nonlinear rig, paper experiment, seed {seed}")
    print("| model | estimation fit % | validation fit % |")
    print("|---|---|---|")
    row("1. ARX(8, 8, 0), two integrators, default method", linear)

    ideal = Sensors(encoder_lines=None, accel_noise=0.0, tach_noise=0.0)
    exact = rig.simulate(exp.torque(), fs=exp.fs, rng=seed, sensors=ideal)
    row("2. the rig itself, no noise or quantisation", exact.hub_angle)

    stuck = binary_opening(np.abs(rec.hub_velocity) < 0.02, np.ones(10, bool))
    share = 100 * stuck[ne:].mean()
    row(
        f"3. ARX, error zero while the hub is stuck ({share:.0f} % of the validation)",
        np.where(stuck, data.y, linear),
    )

    b, a = arx.polynomials
    scale = float(np.std(np.diff(est.y)))
    u = data.u

    def friction(a, b, alpha, beta):
        return _friction_at_input(a, b, alpha, beta, u, scale)

    grid = [
        (fit_percent(est.y, friction(a, b, al, be)[:ne]), al, be)
        for be in (1.0, 3.0, 10.0, 30.0, 100.0)
        for al in (-0.05, -0.02, -0.01, -0.003, 0.003, 0.01, 0.02, 0.05)
    ]
    _, al, be = max(grid)
    row(
        f"4a. ARX + friction at the input, grid (alpha {al:g}, beta {be:g})",
        friction(a, b, al, be),
    )
    aa, bb, al, be = _refit(a, b, al, be, u, est.y, scale)
    row(
        f"4b. the same, every coefficient refitted (alpha {al:.4f}, beta {be:.1f})",
        friction(aa, bb, al, be),
    )
    free = FlexibleManipulator(torque_limit=rig.torque_limit)
    lin_est = exp.run(rig=free, rng=seed).iodata("hub_angle").split(2 / 3)[0]
    bl, al_ = identify(lin_est, ARX(8, 8, 0), integrator=2, rng=seed).polynomials
    aa, bb, al, be = _refit(al_, bl, rig.coulomb_friction, 10.0, u, est.y, scale)
    row(
        "4c. refitted from the friction-free rig's ARX and the true Coulomb level "
        f"(alpha {al:.4f}, beta {be:.1f})",
        friction(aa, bb, al, be),
    )

    narx = identify(
        est,
        NARX(7, 8, 0, integrator=2),
        method="oe",
        holdout=0.0,
        decay=0.0,
        max_rounds=200,
        rng=seed,
    )
    row(
        "5. NARX(7, 8, 0, integrator=2), oe, nothing held back, no decay: "
        f"{narx.result.nit} of 200 rounds",
        narx.simulate(data.u),
    )
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
