"""How long a linear grey box of nine parameters takes to fit.

Three masses in a chain from a wall (springs ``k1``-``k3``, dampers
``c1``-``c3``, masses ``m1``-``m3``: 9 parameters, 6 states), a force on
the first mass, its position measured (as a hub angle is), as
``ss(p) -> (A, B, C, D)`` (MATLAB's ``idgrey``). The record: 2,000
samples at 0.01 s of a random force held over 10 samples, the output with
white noise of 2 % of its RMS, from the true parameters. The start: each
parameter off the truth by a factor ``exp(U(-0.5, 0.5))``, bounds a factor
10 either side of the start (log scale).

For each seed of ``--seeds`` the whole default fit ``identify(data, box,
rng=seed)`` (the learned-metric spiral, the polish, and the same over
growing horizons) is timed, wall and processor seconds, after a first
simulation that compiles (or loads from Numba's cache) the zero-order hold
and the run, timed separately; printed with the simulations run, the cost
(eq. (2): about 2 at the truth, the noise's 2 %) and the largest relative
error of a parameter. The script also prints one simulation's
milliseconds and its largest difference from SciPy's ``cont2discrete`` and
``dlsim``.

BLAS runs on one thread unless set (``OPENBLAS_NUM_THREADS``, as the
command line does): the fit's QR factorisations are 2,000 x 9, where a
threaded BLAS on a loaded machine costs more than it saves. Seconds are
the machine's; compare processor seconds on a loaded one.

    python benchmarks/greybox_linear.py --seeds 0-4
"""

from __future__ import annotations

import argparse
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import time

import numpy as np
from _cli import seed_list
from scipy import signal

from spiralid.sysid import GreyBox, IOData, Parameter, identify

NAMES = ["m1", "m2", "m3", "k1", "k2", "k3", "c1", "c2", "c3"]
UNITS = ["kg"] * 3 + ["N/m"] * 3 + ["N s/m"] * 3
TRUTH = np.array([1.0, 0.5, 0.8, 200.0, 150.0, 100.0, 1.0, 0.6, 0.4])
TS, N = 0.01, 2000


def chain_ss(p):
    """``(A, B, C, D)`` of the chain: states the three positions, then the
    three velocities; the force on mass 1, its position measured."""
    m1, m2, m3, k1, k2, k3, c1, c2, c3 = p
    a = np.zeros((6, 6))
    a[0, 3] = a[1, 4] = a[2, 5] = 1.0
    stiff = np.array([[k1 + k2, -k2, 0.0], [-k2, k2 + k3, -k3], [0.0, -k3, k3]])
    damp = np.array([[c1 + c2, -c2, 0.0], [-c2, c2 + c3, -c3], [0.0, -c3, c3]])
    inv_m = np.array([[1 / m1], [1 / m2], [1 / m3]])
    a[3:, :3] = -inv_m * stiff
    a[3:, 3:] = -inv_m * damp
    b = np.zeros((6, 1))
    b[3, 0] = 1 / m1
    c = np.zeros((1, 6))
    c[0, 0] = 1.0
    return a, b, c, np.zeros((1, 1))


def problem() -> tuple[GreyBox, IOData]:
    rng = np.random.default_rng(0)
    start = TRUTH * np.exp(rng.uniform(-0.5, 0.5, TRUTH.size))
    box = GreyBox(
        [
            Parameter(n, s, (s / 10, s * 10), unit)
            for n, s, unit in zip(NAMES, start, UNITS, strict=True)
        ],
        ss=chain_ss,
    )
    u = np.repeat(rng.standard_normal(N // 10), 10)
    y = box.simulate(TRUTH, u, TS)
    y = y + 0.02 * np.sqrt(np.mean(y**2)) * rng.standard_normal(N)
    return box, IOData(u, y, ts=TS)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=seed_list, default=list(range(5)))
    args = parser.parse_args()
    print(f"OPENBLAS_NUM_THREADS={os.environ['OPENBLAS_NUM_THREADS']}")
    t0 = time.perf_counter()
    box, data = problem()  # its first simulation compiles
    print(f"first simulation (compiles or loads the cache): "
          f"{time.perf_counter() - t0:.2f} s")  # fmt: skip
    start = box.initial_values
    t0, runs = time.process_time(), 200
    for _ in range(runs):
        y = box.simulate(start, data.u, TS)
    per_run = (time.process_time() - t0) / runs
    matrices = tuple(np.asarray(m, dtype=float) for m in chain_ss(start))
    _, y_ref, _ = signal.dlsim(signal.cont2discrete(matrices, TS, "zoh"), data.u)
    print(f"one simulation: {1e3 * per_run:.3f} ms of processor time; largest "
          f"|y - SciPy's| {np.max(np.abs(y - y_ref[:, 0])):.1e} "
          f"(output RMS {np.sqrt(np.mean(y**2)):.1e})")  # fmt: skip
    print("seed | wall s | processor s | simulations | cost | largest rel. error")
    for seed in args.seeds:
        wall, cpu = time.perf_counter(), time.process_time()
        model = identify(data, box, rng=seed)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        error = np.max(np.abs(model.values / TRUTH - 1))
        print(f"{seed:4d} | {wall:6.2f} | {cpu:11.2f} | {model.nfev:11d} | "
              f"{model.cost:5.3f} | {error:.2%}", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
