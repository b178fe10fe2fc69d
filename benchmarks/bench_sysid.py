"""Speed and quality of the paper's cost and of one Eb-SDA identification.

Record: the simulated rig (``spiralid.fms``), a bang-bang experiment of
4050 samples at 500 Hz whose first 2/3 (2700 samples) is the estimation
part; if ``spiralid.fms`` is unavailable, the real arm record tiled to the
same length. Structure ARX(8, 8, 0), population m = 100 stable candidates.

Prints: cost evaluations per second for each predictor (targets >= 1e6/s
one-step, >= 2e4/s simulation), a per-candidate ``lfilter`` loop for
comparison, and one Eb-SDA identification (50 points x 500 iterations) per
predictor: wall time, final cost, and the ratio to the best known cost
(least squares for one-step, output error for simulation). Then the
output-error method itself: wall time on this record and, on the real arm
(ARX(8, 8, 0), first 2/3, free run of the whole record from rest scored on
the last 1/3), least squares and output error side by side.

Run: ``.venv/bin/python benchmarks/bench_sysid.py``. BLAS is pinned to one
thread: on a shared 2-core machine OpenBLAS threads oversubscribe and
small dense kernels get tens of times slower.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import time
from pathlib import Path

import numpy as np
from scipy.signal import lfilter

from spiralid.sysid import ARX, IOData, PaperCost, identify, validate
from spiralid.sysid.identify import (
    default_bounds,
    feasible_initial_points,
)

ARM = (
    Path(__file__).resolve().parents[1]
    / ".."
    / "shared"
    / "data"
    / "daisy_robot_arm.csv"
)


def record() -> tuple[IOData, str]:
    try:
        from spiralid.fms import Experiment

        exp = Experiment(duration=8.1, n_pulses=8)
        data = exp.run(rng=0).iodata("end_acceleration")
        return data, "simulated rig, 8 bang-bang pulses, 4050 samples at 500 Hz"
    except ImportError:
        arm = IOData.from_csv(ARM, ts=0.01)
        reps = int(np.ceil(4050 / arm.n))
        u, y = np.tile(arm.u, reps)[:4050], np.tile(arm.y, reps)[:4050]
        return IOData(u, y, ts=0.01), "real arm tiled to 4050 samples"


def rate(fn, arg, repeats=7, per_repeat=0.3) -> tuple[float, float]:
    """Candidate evaluations per second: (median, best) over `repeats` runs."""
    fn(arg)  # compile / warm up
    rates = []
    for _ in range(repeats):
        n, t0 = 0, time.perf_counter()
        while (elapsed := time.perf_counter() - t0) < per_repeat:
            fn(arg)
            n += 1
        rates.append(n * len(arg) / elapsed)
    return float(np.median(rates)), float(np.max(rates))


def main() -> None:
    data, what = record()
    est, _ = data.split(2 / 3)
    arx = ARX(8, 8, 0)
    print(f"record: {what}; estimation samples: {est.n}; structure {arx}")
    box = default_bounds(est, arx)
    thetas = feasible_initial_points(box, arx, 100, rng=0)

    print("\ncost evaluations per second (m = 100 candidates per call)")
    for predictor, target in (("one-step", 1e6), ("simulation", 2e4)):
        cost = PaperCost(arx, est, predictor=predictor)
        med, best = rate(cost, thetas)
        print(
            f"  {predictor:<10} median {med:10.4g} /s  best {best:10.4g} /s"
            f"   (target {target:.0e})"
        )

    cost = PaperCost(arx, est, predictor="simulation")

    def loop(ths):
        for th in ths:
            num, den = arx.polynomials(th)
            e = est.y[cost.t0 :] - lfilter(num, den, est.u)[cost.t0 :]
            np.sqrt(e @ e)

    med, best = rate(loop, thetas)
    print(f"  lfilter per-candidate loop (reference): median {med:.4g} /s")

    print("\none Eb-SDA identification, 50 points x 500 iterations, rng=0")
    refs = {
        "one-step": identify(est, arx, method="ls", predictor="one-step"),
        "simulation": identify(est, arx, method="oe", predictor="simulation"),
    }
    for predictor, ref in refs.items():
        for par in ("coefficients", "reflection"):
            t0 = time.perf_counter()
            fit = identify(
                est, arx, method="ebsda", predictor=predictor,
                parametrization=par, rng=0, n_points=50, max_iter=500,
            )  # fmt: skip
            wall = time.perf_counter() - t0
            print(
                f"  {predictor:<10} {par:<12} wall {wall:6.2f} s  "
                f"cost {fit.cost:10.4f}  best known ({ref.method}) {ref.cost:8.4f}  "
                f"ratio {fit.cost / ref.cost:8.3f}  nfev {fit.result.nfev}"
            )

    print("\noutput error (least squares and Steiglitz-McBride starts)")
    walls = []
    for _ in range(3):
        t0 = time.perf_counter()
        oe = identify(est, arx, method="oe")
        walls.append(time.perf_counter() - t0)
    print(
        f"  this record: wall median {np.median(walls):.2f} s  cost {oe.cost:.4f}  "
        f"start kept {oe.result.start!r}  nfev {oe.result.nfev}"
    )
    if ARM.exists():
        arm = IOData.from_csv(ARM, ts=0.01)
        a_est, a_val = arm.split(2 / 3)
        for method in ("ls", "oe"):
            t0 = time.perf_counter()
            fit = identify(a_est, arx, method=method)
            wall = time.perf_counter() - t0
            rep = validate(fit, a_val, warmup=a_est)
            print(
                f"  real arm {method:<3} wall {wall:5.2f} s  estimation cost "
                f"{fit.cost:7.4f}  validation fit {rep.fit_percent:6.2f} %  "
                f"max |pole| {rep.max_pole_radius:.7f}"
            )


if __name__ == "__main__":
    main()
