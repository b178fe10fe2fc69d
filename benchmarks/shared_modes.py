"""Several sensors, one set of modes (issue 30): the shared-denominator fit
against each sensor alone, on the simulated rig.

Setup: ``FlexibleManipulator()`` (the default rig: modal damping 0.02, no
hub friction) and ``paper_experiment()`` with the sensors' default noise,
one noise seed per realisation; the first 2/3 estimate. Truth: the FEM's
undamped natural frequencies ``rig.modes(3)`` and the damping ratio 0.02,
exactly what the sampled model's poles hold (benchmarks/mode_intervals.py
says why). The rig records the tip deflection noise-free, so white noise of
``--tip-noise`` (default 1 %) of its RMS is added to it. Outputs:
``end_acceleration`` and ``tip_deflection`` by default (the hub angle and
velocity integrate the torque, and a shared model has no per-output
integrator yet). Structure: ARX(12, 12, 1), the acceleration's true order
(mode_intervals.py: every resonance below Nyquist and the anti-aliasing
filter). The tip deflection is not filtered, so its denominator lacks the
filter's poles that the acceleration's has: one shared denominator is then
a compromise between them.

For each realisation: ``identify(est, ARX)`` on the record of every output
(one shared denominator, noise weights from the fit) by the default
``"spiral"`` and by ``"oe"`` and ``"ls"`` for the same structure, the
subspace (PO-MOESP) poles of the same order as a baseline, and on
each output alone (the default ``"spiral"``); each FEM mode is matched to the nearest
identified mode. Prints per mode the mean and largest frequency error (%),
the mean damping error (%), the coverage of the 95 % frequency intervals,
and the wall times (multi-output against the sum of the single-output
fits). Asserts nothing.

Run: ``python benchmarks/shared_modes.py [--seeds 20] [--workers 2]
[--outputs end_acceleration,tip_deflection] [--order 12,12,1]
[--tip-noise 0.01]``.
"""

import os

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace

import numpy as np

from spiralid.fms import FlexibleManipulator, paper_experiment
from spiralid.sysid import ARX, identify
from spiralid.sysid.estimation.subspace import subspace_denominator
from spiralid.sysid.models.modes import mode_table

ZETA = 0.02


def _matched(table, truth):
    """Frequency, damping and the 95 % frequency interval of the identified
    mode nearest each true frequency."""
    out = []
    for f in truth:
        i = int(np.argmin(np.abs(table.frequency - f)))
        lo, hi = table.frequency_interval[i]
        out.append((table.frequency[i], table.damping[i], lo, hi))
    return np.array(out)


def _with_tip_noise(data, seed: int, share: float):
    """The record with white noise of `share` times its RMS added to the tip
    deflection, which the rig records noise-free (a strain gauge's noise is
    not modelled); the other outputs keep their sensors' noise."""
    if "tip_deflection" not in data.output_names or share == 0:
        return data
    k = data.output_names.index("tip_deflection")
    y = data.outputs.copy()
    rng = np.random.default_rng([seed, 30])
    y[:, k] += share * np.sqrt(np.mean(y[:, k] ** 2)) * rng.standard_normal(data.n)
    return replace(data, y=y if data.n_outputs > 1 else y[:, 0])


def run_one(task) -> dict:
    seed, outputs, order, tip_noise = task
    rig = FlexibleManipulator()
    truth = rig.modes(3)
    data = paper_experiment().run(rig, rng=seed).iodata(list(outputs))
    est = _with_tip_noise(data, seed, tip_noise).split(2 / 3)[0]
    arx = ARX(*order)
    times, rows = {}, {}
    # The subspace baseline: PO-MOESP's poles of order na, no iteration.
    t0 = time.perf_counter()
    a = subspace_denominator(est, arx.na)
    times["shared subspace"] = time.perf_counter() - t0
    rows["shared subspace"] = _matched(mode_table(a, [1.0], est.ts), truth)
    for method in ("spiral", "oe", "ls"):
        t0 = time.perf_counter()
        shared = identify(est, arx, method=method, rng=seed)
        times[f"shared {method}"] = time.perf_counter() - t0
        rows[f"shared {method}"] = _matched(shared.modes.table, truth)
    for name in outputs:
        t0 = time.perf_counter()
        single = identify(est.output(name), arx, rng=seed)
        times[name] = time.perf_counter() - t0
        rows[name] = _matched(single.modes, truth)
    return dict(seed=seed, rows=rows, times=times, truth=truth)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--outputs", default="end_acceleration,tip_deflection")
    ap.add_argument("--order", default="12,12,1")
    ap.add_argument(
        "--tip-noise",
        type=float,
        default=0.01,
        help="white noise on the tip deflection, a share of its RMS",
    )
    args = ap.parse_args(argv)
    outputs = tuple(args.outputs.split(","))
    order = tuple(int(v) for v in args.order.split(","))
    tasks = [(s, outputs, order, args.tip_noise) for s in range(args.seeds)]
    t0 = time.perf_counter()
    identify(  # compile the kernels once, outside the timings
        paper_experiment().run(FlexibleManipulator(), rng=0).iodata(list(outputs)),
        ARX(2, 2, 1),
        rng=0,
        max_nfev=200,
    )
    if args.workers > 1:
        with ProcessPoolExecutor(args.workers) as pool:
            runs = list(pool.map(run_one, tasks, chunksize=1))
    else:
        runs = [run_one(t) for t in tasks]
    truth = runs[0]["truth"]
    print(
        f"ARX{order}, outputs {', '.join(outputs)} (tip noise {args.tip_noise:g} "
        f"of its RMS), {len(runs)} noise seeds; FEM "
        f"modes {', '.join(f'{f:.4f}' for f in truth)} Hz, damping {ZETA}\n"
    )
    print(
        "| fit | mode | mean freq error % | max freq error % | mean damping "
        "error % | 95 % interval covers |"
    )
    print("|---|---|---|---|---|---|")
    for fit in ("shared spiral", "shared oe", "shared ls", "shared subspace", *outputs):
        got = np.array([r["rows"][fit] for r in runs])  # (seeds, modes, 4)
        for k, f in enumerate(truth):
            err = 100 * np.abs(got[:, k, 0] - f) / f
            derr = 100 * np.abs(got[:, k, 1] - ZETA) / ZETA
            covers = np.mean((got[:, k, 2] <= f) & (f <= got[:, k, 3]))
            print(
                f"| {fit} | {k + 1} | {err.mean():.3f} | {err.max():.3f} | "
                f"{derr.mean():.1f} | {100 * covers:.0f} % |"
            )
    shared_t = np.median([r["times"]["shared spiral"] for r in runs])
    singles_t = np.median([sum(r["times"][o] for o in outputs) for r in runs])
    print(
        f"\nmedian time: shared spiral {shared_t:.2f} s, the {len(outputs)} "
        "single-output "
        f"fits together {singles_t:.2f} s (ratio {shared_t / singles_t:.2f}); "
        f"{time.perf_counter() - t0:.0f} s in all, load average "
        f"{os.getloadavg()[0]:.2f}"
    )


if __name__ == "__main__":
    main()
