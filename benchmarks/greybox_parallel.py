"""A grey-box fit on several processes: wall time against the number of
workers, and the same fit bit for bit.

The structure is a Duffing oscillator (a mass on a hardening spring) with a
plain Python ``f``, 1,000 samples and 4 Runge-Kutta steps per sample, so
one simulation is tens of milliseconds of Python and the fit's time is its
simulations'. For each method (the learned-metric ``spiral``, which polls
two points at a time, and the paper's ``ebsda``, a population of 20 at a
time) it fits with ``workers`` 1 (no pool), 2, 3 and 4, and prints the wall
time, the speed-up over one process, and whether the parameters and the
cost equal the one-process fit's bit for bit. Wall time of one run per row,
on whatever else the machine is doing; the pool's start-up is included.

Run: ``python benchmarks/greybox_parallel.py [--workers 1,2,3,4]
[--max-nfev 100]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import spiralid as sid
from spiralid.sysid import GreyBox, Parameter

TRUE = (4.0, 0.3, 2.0)  # stiffness, damping, cubic stiffness


def duffing_f(t, x, u, p):
    k, c, k3 = p
    return np.array([x[1], u[0] - k * x[0] - c * x[1] - k3 * x[0] ** 3])


def duffing_g(x, u, p):
    return x[0]


def structure() -> GreyBox:
    params = [
        Parameter("k", 2.0, (0.5, 20.0), "N/m"),
        Parameter("c", 0.1, (0.01, 5.0), "N s/m"),
        Parameter("k3", 1.0, (0.05, 20.0), "N/m^3"),
    ]
    return GreyBox(params, f=duffing_f, g=duffing_g, n_states=2, substeps=4)


def record(n: int = 1000) -> sid.IOData:
    rng = np.random.default_rng(0)
    u = np.repeat(rng.standard_normal(n // 20), 20)
    y = structure().simulate(TRUE, u, 0.05)
    return sid.IOData(u, y + 0.01 * np.std(y) * rng.standard_normal(n), ts=0.05)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", default="1,2,3,4")
    parser.add_argument("--max-nfev", type=int, default=100)
    args = parser.parse_args(argv)
    counts = [int(w) for w in args.workers.split(",")]
    data = record()
    t = time.perf_counter()
    structure().simulate(TRUE, data.u, data.ts)
    print(f"one simulation: {1e3 * (time.perf_counter() - t):.0f} ms")
    print("method   workers   wall s   speed-up   same as 1 worker")
    for method in ("spiral", "ebsda"):
        first = None
        for workers in counts:
            t = time.perf_counter()
            model = sid.identify(
                data, structure(), method, rng=1, max_nfev=args.max_nfev,
                workers=workers,
            )  # fmt: skip
            wall = time.perf_counter() - t
            if first is None:
                first = (model, wall)
            same = np.array_equal(model.params, first[0].params) and (
                model.cost == first[0].cost
            )
            print(
                f"{method:8} {workers:7d} {wall:8.1f} {first[1] / wall:9.2f}x   "
                f"{'yes' if same else 'NO'}"
            )


if __name__ == "__main__":
    main()
