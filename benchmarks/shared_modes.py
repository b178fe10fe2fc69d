"""Several sensors, one set of modes (issue 30): the shared-denominator fit
against each sensor alone, on the simulated rig, and the calibration of its
95 % intervals.

Setup: ``FlexibleManipulator()`` (the default rig: modal damping 0.02, no
hub friction) and ``paper_experiment()`` with the sensors' default noise,
one noise seed per realisation; the first 2/3 estimate. Truth: the FEM's
undamped natural frequencies ``rig.modes(3)`` and the damping ratio 0.02,
exactly what the sampled model's poles hold (benchmarks/mode_intervals.py
says why). The rig records deflections noise-free, so white noise of
``--tip-noise`` (default 1 %) of its RMS is added to the tip deflection and
to any ``deflection_<x>``.

Outputs (``--outputs``): any of the rig's, ``all`` for the four channels
(hub angle, hub velocity, end-point acceleration, tip deflection), and
``node`` for an accelerometer at the outer node of mode 2 (the inertial
frame's, ``rig.mode_nodes(2, frame="inertial")[-1]``, 0.832 of the
length: it barely sees mode 2). Default ``end_acceleration,
tip_deflection``. Each output's known integrators (``--integrator``, by
default from its name: 2 for the hub angle, 1 for the hub velocity, 0
otherwise) are outside the shared denominator.

Structure (``--order``, default ARX(12, 12, 1)). The true order of one
shared ``A``: the five modes below Nyquist (13, 35, 65, 116, 188 Hz; 10
poles) and, when a filtered channel (hub velocity, accelerometers) is
among the outputs, the 4th-order anti-aliasing filter (4 poles): na = 14.
An unfiltered output (hub angle, deflections) then needs the filter's
poles cancelled by its numerator: its own numerator (nb = its order, nk =
1) times the filter's 4th-degree polynomial, nb + 4. The largest is the
hub angle's: 2 integrators and 10 mode poles, nb = 12 + 4 = 16. So four
outputs: ARX(14, 16, 1). ARX(12, 12, 1), the acceleration's (mode_intervals.py),
squeezes the filter into one pair, which the unfiltered outputs cannot
cancel exactly.

For each realisation: ``identify(est, ARX, integrator=...)`` on the record
of every output (one shared denominator, noise weights from the fit) by
each of ``--methods`` (default ``spiral,oe,ls,subspace``; the subspace
(PO-MOESP) poles only when every output has the same integrators), and on
each output alone (the default ``"spiral"``, its own integrators; off with
``--no-singles``); each FEM mode is matched to the nearest identified
mode. Prints per fit and mode the mean and largest frequency error (%),
the mean damping error (%), the mean and spread of the frequency's error
in standard errors (calibrated intervals: 0 and 1), and the coverage of
the 95 % frequency and damping intervals with the count's Clopper-Pearson
95 % range; and the wall times (multi-output against the sum of the
single-output fits). The range of counts a calibrated 95 % interval gives
(the binomial's 2.5-97.5 % quantiles) is printed once. Asserts nothing.

``--realisations N`` is the calibration run: N noise realisations (seeds
0..N-1, or from ``--first-seed``) of the shared spiral fit alone (unless
``--methods`` or ``--singles`` say otherwise).

Run: ``python benchmarks/shared_modes.py [--seeds 20] [--workers 2]
[--outputs end_acceleration,tip_deflection] [--order 12,12,1]
[--integrator auto] [--methods spiral,oe,ls,subspace] [--no-singles]
[--tip-noise 0.01] [--realisations 100]``; four outputs at their true
order: ``--outputs all --order 14,16,1``.
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
from scipy import stats

from spiralid.fms import FlexibleManipulator, paper_experiment
from spiralid.sysid import ARX, identify
from spiralid.sysid.estimation.shared.subspace import subspace_denominator
from spiralid.sysid.models.modes import mode_table

ZETA = 0.02
FOUR = ("hub_angle", "hub_velocity", "end_acceleration", "tip_deflection")
INTEGRATORS = {"hub_angle": 2, "hub_velocity": 1}
METHODS = ("spiral", "oe", "ls", "subspace")


def node_position(rig: FlexibleManipulator) -> float:
    """Mode 2's outer node for an accelerometer (the inertial frame)."""
    return float(rig.mode_nodes(2, frame="inertial")[-1])


def experiment(rig: FlexibleManipulator, outputs):
    """The paper's experiment, with the node accelerometer if asked for."""
    exp = paper_experiment()
    if "node" in outputs:
        exp = replace(exp, acceleration_at=(node_position(rig),))
    names = [exp.sensors().positional_names[0] if o == "node" else o for o in outputs]
    return exp, names


def _matched(table, truth):
    """Frequency, damping, the 95 % frequency interval and the 95 % damping
    interval of the identified mode nearest each true frequency."""
    out = []
    for f in truth:
        i = int(np.argmin(np.abs(table.frequency - f)))
        lo, hi = table.frequency_interval[i]
        zlo, zhi = table.damping_interval[i]
        out.append((table.frequency[i], table.damping[i], lo, hi, zlo, zhi))
    return np.array(out)


def _with_tip_noise(data, seed: int, share: float):
    """The record with white noise of `share` times its RMS added to each
    deflection (the tip's and any ``deflection_<x>``), which the rig records
    noise-free (a strain gauge's noise is not modelled); the other outputs
    keep their sensors' noise. The tip's stream is ``[seed, 30]``, as
    before the other deflections were added."""
    if share == 0:
        return data
    y = data.outputs.copy()
    for k, name in enumerate(data.output_names):
        if name == "tip_deflection":
            rng = np.random.default_rng([seed, 30])
        elif name.startswith("deflection_"):
            rng = np.random.default_rng([seed, 30, k + 1])
        else:
            continue
        rms = np.sqrt(np.mean(y[:, k] ** 2))
        y[:, k] += share * rms * rng.standard_normal(data.n)
    return replace(data, y=y if data.n_outputs > 1 else y[:, 0])


def run_one(task) -> dict:
    seed, outputs, order, integrators, tip_noise, methods, singles = task
    rig = FlexibleManipulator()
    truth = rig.modes(3)
    exp, names = experiment(rig, outputs)
    data = exp.run(rig, rng=seed).iodata(names)
    est = _with_tip_noise(data, seed, tip_noise).split(2 / 3)[0]
    arx = ARX(*order)
    times, rows = {}, {}
    for method in methods:
        t0 = time.perf_counter()
        if method == "subspace":
            # PO-MOESP's poles of order na, no iteration, no interval.
            table = mode_table(subspace_denominator(est, arx.na), [1.0], est.ts)
        else:
            shared = identify(est, arx, method=method, rng=seed, integrator=integrators)
            table = shared.modes.table
        times[f"shared {method}"] = time.perf_counter() - t0
        rows[f"shared {method}"] = _matched(table, truth)
    for name, k in zip(names, integrators, strict=True) if singles else ():
        t0 = time.perf_counter()
        single = identify(est.output(name), arx, rng=seed, integrator=k)
        times[name] = time.perf_counter() - t0
        rows[name] = _matched(single.modes, truth)
    return dict(seed=seed, rows=rows, times=times, truth=truth, names=names)


def _coverage(hits: np.ndarray) -> str:
    """The coverage and its Clopper-Pearson 95 % range, in percent."""
    n, k = hits.size, int(np.sum(hits))
    ci = stats.binomtest(k, n).proportion_ci(0.95)
    return f"{100 * k / n:.0f} % [{100 * ci.low:.0f}, {100 * ci.high:.0f}]"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument(
        "--realisations",
        type=int,
        default=None,
        help="the calibration run: this many seeds, the shared spiral fit only",
    )
    ap.add_argument(
        "--first-seed",
        type=int,
        default=0,
        help="the first noise seed (a second calibration run takes others)",
    )
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--outputs", default="end_acceleration,tip_deflection")
    ap.add_argument("--order", default="12,12,1")
    ap.add_argument(
        "--integrator",
        default="auto",
        help="each output's known integrators, or 'auto' (by its name)",
    )
    ap.add_argument("--methods", default=None, help=f"of {','.join(METHODS)}")
    ap.add_argument("--singles", action=argparse.BooleanOptionalAction, default=None)
    ap.add_argument(
        "--tip-noise",
        type=float,
        default=0.01,
        help="white noise on each deflection, a share of its RMS",
    )
    args = ap.parse_args(argv)
    outputs = args.outputs.split(",")
    if outputs == ["all"]:
        outputs = list(FOUR)
    order = tuple(int(v) for v in args.order.split(","))
    if args.integrator == "auto":
        integrators = tuple(INTEGRATORS.get(o, 0) for o in outputs)
    else:
        integrators = tuple(int(v) for v in args.integrator.split(","))
    calibration = args.realisations is not None
    seeds = args.realisations if calibration else args.seeds
    if args.methods is not None:
        methods = tuple(args.methods.split(","))
    else:
        methods = ("spiral",) if calibration else METHODS
    if len(set(integrators)) > 1:
        # Outputs with other integrators have other inputs: no one subspace.
        methods = tuple(m for m in methods if m != "subspace")
    singles = (not calibration) if args.singles is None else args.singles
    tasks = [
        (s, outputs, order, integrators, args.tip_noise, methods, singles)
        for s in range(args.first_seed, args.first_seed + seeds)
    ]
    t0 = time.perf_counter()
    rig = FlexibleManipulator()
    exp, names = experiment(rig, outputs)
    identify(  # compile the kernels once, outside the timings
        exp.run(rig, rng=0).iodata(names),
        ARX(2, 2, 1),
        rng=0,
        max_nfev=200,
        integrator=integrators,
    )
    if args.workers > 1:
        with ProcessPoolExecutor(args.workers) as pool:
            runs = list(pool.map(run_one, tasks, chunksize=1))
    else:
        runs = [run_one(t) for t in tasks]
    truth = runs[0]["truth"]
    n = len(runs)
    print(
        f"ARX{order}, outputs {', '.join(names)} (integrators {integrators}; "
        f"deflection noise {args.tip_noise:g} of its RMS), {n} noise seeds; "
        f"FEM modes {', '.join(f'{f:.4f}' for f in truth)} Hz, damping {ZETA}"
    )
    if "node" in outputs:
        print(f"node accelerometer at {node_position(rig):.4f} of the length")
    lo, hi = (int(stats.binom.ppf(q, n, 0.95)) for q in (0.025, 0.975))
    print(
        f"a calibrated 95 % interval covers {lo}-{hi} of {n} realisations "
        "(binomial 2.5-97.5 %)\n"
    )
    print(
        "| fit | mode | mean freq error % | max freq error % | mean damping "
        "error % | freq error / se: mean, sd | frequency interval covers "
        "[95 % range] | damping interval covers [95 % range] |"
    )
    print("|---|---|---|---|---|---|---|---|")
    fits = [f"shared {m}" for m in methods] + (names if singles else [])
    for fit in fits:
        got = np.array([r["rows"][fit] for r in runs])  # (seeds, modes, 6)
        for k, f in enumerate(truth):
            err = 100 * np.abs(got[:, k, 0] - f) / f
            derr = 100 * np.abs(got[:, k, 1] - ZETA) / ZETA
            se = (got[:, k, 3] - got[:, k, 2]) / (2 * stats.norm.ppf(0.975))
            with np.errstate(all="ignore"):
                z = (got[:, k, 0] - f) / se
            if np.all(np.isnan(se)):
                zs = fcov = dcov = "no interval"
            else:
                # A zero-width interval (se 0) covers nothing: it counts as a
                # miss, and its infinite error in se is left out of the mean.
                ok = np.isfinite(z)
                zs = f"{z[ok].mean():+.2f}, {z[ok].std(ddof=1):.2f}"
                if not np.all(ok):
                    zs += f" ({np.count_nonzero(~ok)} with se 0)"
                fcov = _coverage((got[:, k, 2] <= f) & (f <= got[:, k, 3]))
                dcov = _coverage((got[:, k, 4] <= ZETA) & (ZETA <= got[:, k, 5]))
            print(
                f"| {fit} | {k + 1} | {err.mean():.4f} | {err.max():.4f} | "
                f"{derr.mean():.1f} | {zs} | {fcov} | {dcov} |"
            )
    shared_t = np.median([r["times"][f"shared {methods[0]}"] for r in runs])
    line = f"\nmedian time: shared {methods[0]} {shared_t:.2f} s"
    if singles:
        singles_t = np.median([sum(r["times"][o] for o in names) for r in runs])
        line += (
            f", the {len(names)} single-output fits together {singles_t:.2f} s "
            f"(ratio {shared_t / singles_t:.2f})"
        )
    print(
        f"{line}; {time.perf_counter() - t0:.0f} s in all, load average "
        f"{os.getloadavg()[0]:.2f}"
    )


if __name__ == "__main__":
    main()
