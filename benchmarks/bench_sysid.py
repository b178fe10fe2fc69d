"""Speed and quality of the paper's cost and of one Eb-SDA identification.

Record: the simulated rig (``spiralid.fms``), a bang-bang experiment of
4050 samples at 500 Hz whose first 2/3 (2700 samples) is the estimation
part; if ``spiralid.fms`` is unavailable, the real arm record tiled to the
same length. Structure ARX(8, 8, 0), population m = 100 stable candidates.

Prints: cost evaluations per second for each predictor, the simulation
under both initial conditions (``initial="rest"``, the default, and
``"measured"``) (targets >= 1e6/s one-step, >= 2e4/s simulation), a
per-candidate ``lfilter`` loop for comparison, and one Eb-SDA identification
(50 points x 500 iterations) per predictor: wall time, final cost, and the
ratio to the best known cost (least squares for one-step, output error for
simulation). Then the output-error method itself under both initial
conditions: wall time, estimation costs and validation fit on this record
and on the real arm (ARX(8, 8, 0), first 2/3, free run of the whole record
from rest scored on the last 1/3), least squares beside it.

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

import spiralid.datasets
from spiralid.sysid import ARX, IOData, PaperCost, identify, validate
from spiralid.sysid.estimation.linear.parametrizations import (
    default_bounds,
    feasible_initial_points,
)

# The DaISy arm record shipped with the package (spiralid.datasets).
ARM = Path(spiralid.datasets.__file__).with_name("daisy_robot_arm.csv")


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
    for predictor, initial, target in (
        ("one-step", "rest", 1e6),
        ("simulation", "rest", 2e4),
        ("simulation", "measured", 2e4),
    ):
        cost = PaperCost(arx, est, predictor=predictor, initial=initial)
        med, best = rate(cost, thetas)
        label = predictor if predictor == "one-step" else f"{predictor}/{initial}"
        print(
            f"  {label:<19} median {med:10.4g} /s  best {best:10.4g} /s"
            f"   (target {target:.0e})"
        )

    def loop(ths):
        for th in ths:
            num, den = arx.polynomials(th)
            e = est.y - lfilter(num, den, est.u)
            np.sqrt(e @ e)

    med, best = rate(loop, thetas)
    print(f"  lfilter per-candidate loop (reference): median {med:.4g} /s")

    print("\none Eb-SDA identification, 50 points x 500 iterations, rng=0")
    refs = {
        ("one-step", "rest"): identify(est, arx, method="ls", predictor="one-step"),
        ("simulation", "rest"): identify(est, arx, method="oe"),
        ("simulation", "measured"): identify(est, arx, method="oe", initial="measured"),
    }
    for (predictor, initial), ref in refs.items():
        label = predictor if predictor == "one-step" else f"{predictor}/{initial}"
        for par in ("coefficients", "reflection"):
            t0 = time.perf_counter()
            fit = identify(
                est, arx, method="ebsda", predictor=predictor, initial=initial,
                parametrization=par, rng=0, n_points=50, max_iter=500,
            )  # fmt: skip
            wall = time.perf_counter() - t0
            print(
                f"  {label:<19} {par:<12} wall {wall:6.2f} s  "
                f"cost {fit.cost:10.4f}  best known ({ref.method}) {ref.cost:8.4f}  "
                f"ratio {fit.cost / ref.cost:8.3f}  nfev {fit.result.nfev}"
            )

    print(
        "\noutput error (least squares and Steiglitz-McBride starts); costs: "
        "eq. (2) from rest / from the measured past; validation: free run of "
        "the whole record from rest, last 1/3"
    )
    records = [("this record", data)]
    if ARM.exists():
        records.append(("real arm", IOData.from_csv(ARM, ts=0.01)))
    for name, whole in records:
        r_est, r_val = whole.split(2 / 3)
        costs = {i: PaperCost(arx, r_est, initial=i) for i in ("rest", "measured")}
        for method, initial in (("ls", "rest"), ("oe", "rest"), ("oe", "measured")):
            walls = []
            for _ in range(3 if method == "oe" else 1):
                t0 = time.perf_counter()
                fit = identify(r_est, arx, method=method, initial=initial)
                walls.append(time.perf_counter() - t0)
            rep = validate(fit, r_val, warmup=r_est)
            label = "ls" if method == "ls" else f"oe/{initial}"
            extra = (
                f"  start {fit.result.start!r} nfev {fit.result.nfev}"
                if method == "oe"
                else ""
            )
            print(
                f"  {name:<11} {label:<11} wall {np.median(walls):5.2f} s  cost "
                f"{costs['rest'](fit.theta):8.4f} / {costs['measured'](fit.theta):8.4f}"
                f"  val fit {rep.fit_percent:6.2f} %  max |pole| "
                f"{rep.max_pole_radius:.7f}{extra}"
            )


if __name__ == "__main__":
    main()
