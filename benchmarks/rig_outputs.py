"""Every output of the simulated rig, with and without known integrators,
against a 50-start multistart.

The rig's hub angle integrates the hub velocity (a pole at z = 1), which
itself integrates the torque less a tiny viscous friction (a second pole at
z = 0.9999997): a model that must find those poles itself stops at its
stability bound or, under the default stability margin, fits them badly.
With ``identify(integrator=k)`` the ``k`` poles are known and the method
estimates the others. Prints, per output and structure: estimation cost
(eq. 2), its ratio to the best cost a 50-start multistart finds in the same
model class (with the integrators factored out when the route uses them),
validation fit % (free run over the whole record, scored on the last
third) and wall time, for output error and the recommended ``spiral``
method (seed 0, default margin), with 0 and 1 integrators (and 2 for the
hub angle), and the machine load.

The multistart: least squares, Steiglitz-McBride and 48 random stable
denominators (``random_stable_polynomial``, seed 0), each with the numerator
least squares gives for it, polished by output error's local method
(``estimation.linear.outputerror.local_polish``); the lowest estimation cost.

Run: ``python benchmarks/rig_outputs.py [--starts 50]``.
"""

import argparse
import os
import time
from dataclasses import replace

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from scipy import signal

from spiralid.fms import FlexibleManipulator, paper_experiment
from spiralid.fms.rig import _OUTPUTS
from spiralid.sysid import ARX, PaperCost, identify, steiglitz_mcbride, validate
from spiralid.sysid.estimation.linear.outputerror import local_polish
from spiralid.sysid.models.arx import arx_least_squares
from spiralid.sysid.models.polynomials import random_stable_polynomial


def _numerator_for(a, est, arx):
    """The least-squares numerator of ``y ~ B / A u`` for a fixed ``A``."""
    v = signal.lfilter([1.0], np.r_[1.0, a], est.u)
    lags = arx.input_lags(v)[:, arx.max_lag :]
    return np.linalg.lstsq(lags.T, est.y[arx.max_lag :], rcond=None)[0]


def multistart(est, arx, n_starts, seed=0) -> float:
    """The lowest estimation cost of `n_starts` polished starts."""
    ls = arx_least_squares(est, arx)
    starts = [ls, steiglitz_mcbride(est, arx, ls)]
    rng = np.random.default_rng(seed)
    for a in random_stable_polynomial(arx.na, size=n_starts - 2, rng=rng):
        starts.append(np.r_[a, _numerator_for(a, est, arx)])
    cost = PaperCost(arx, est)
    return min(float(cost(local_polish(s, arx, est, "simulation")[0])) for s in starts)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--starts", type=int, default=50)
    args = ap.parse_args(argv)
    record = paper_experiment().run(FlexibleManipulator(), rng=0)
    identify(record.iodata().split(2 / 3)[0], ARX(2, 2, 0), rng=0)  # compile
    head = (
        "output | structure | method | integrator | cost | cost / multistart "
        "| validation fit % | time s"
    )
    print(f"| {head} |")
    print("|---|---|---|---|---|---|---|---|")
    for name in _OUTPUTS:
        est, val = record.iodata(name).split(2 / 3)
        # The hub angle integrates twice (the rigid body: torque to angle).
        counts = (0, 1, 2) if name == "hub_angle" else (0, 1)
        for arx in (ARX(4, 4, 1), ARX(8, 8, 0)):
            best = {}
            for count in counts:
                u = est.u
                for _ in range(count):
                    u = np.cumsum(u)
                inner = ARX(arx.na - count, arx.nb, arx.nk)
                best[count] = multistart(replace(est, u=u), inner, args.starts)
            for method in ("oe", "spiral"):
                for count in counts:
                    t0 = time.perf_counter()
                    fit = identify(est, arx, method=method, rng=0, integrator=count)
                    seconds = time.perf_counter() - t0
                    fit_val = validate(fit, val, warmup=est).fit_percent
                    print(
                        f"| {name} | {arx} | {method} | {count} | {fit.cost:.4g} "
                        f"| {fit.cost / best[count]:.4f} | {fit_val:.1f} "
                        f"| {seconds:.2f} |",
                        flush=True,
                    )
    print(f"\nload average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
