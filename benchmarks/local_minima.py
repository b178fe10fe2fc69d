"""Is the spiral's global part worth its evaluations? Records whose output-
error criterion has several local minima, against an independent multistart.

Records (seeded, ``--records`` of each kind): a random lightly damped system
of order 6 or 8 (three or four modes at random frequencies, pole radii
0.90-0.99, a random numerator), driven by white noise low-pass filtered
(4th-order Butterworth) at a cut-off relative to the highest mode, with
output noise at 5 % of the output's RMS, 900 samples, and identified with
fewer modes than it has: an under-modelled output-error criterion is where
several local minima are known to occur (Soderstrom, IEEE TAC 20(6), 1975).
Kinds (modes dropped, cut-off / highest mode): ``drop1`` (1, 1.2),
``drop2-low`` (2, 0.6), ``drop2`` (2, 1.2).

On each record: the best estimation cost a 50-start multistart finds (least
squares, Steiglitz-McBride and 48 random stable denominators, each polished
by output error's local method: ``rig_outputs.multistart``); output error
(two starts); and the recommended ``spiral`` method, seeds 0..``--seeds``-1.
The best is the lowest cost any of them found. Prints per kind, over all
records and over those on which OE is more than 1 % above the best (it
stopped in a local minimum): the median and worst ratio of OE's and
spiral's costs to the best, how many spiral runs end more than 1 % above
it and how many more than 1 % below OE, and the median times.

Run: ``python benchmarks/local_minima.py [--records 10] [--seeds 5]``.
"""

import argparse
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from rig_outputs import multistart
from scipy import signal

from spiralid.sysid import ARX, IOData, identify

# kind -> (modes dropped, low-pass cut-off relative to the highest mode)
KINDS = {"drop1": (1, 1.2), "drop2-low": (2, 0.6), "drop2": (2, 1.2)}


def make_record(kind: str, seed: int) -> tuple[IOData, ARX]:
    dropped, cut = KINDS[kind]
    rng = np.random.default_rng(seed)
    n_modes = int(rng.integers(3, 5))
    freqs = np.sort(rng.uniform(0.08, 0.9, n_modes)) * np.pi
    radii = rng.uniform(0.90, 0.99, n_modes)
    poles = np.concatenate([radii * np.exp(1j * freqs), radii * np.exp(-1j * freqs)])
    a = np.real(np.poly(poles))
    b = rng.standard_normal(2 * n_modes)
    n = 900
    lb, la = signal.butter(4, float(np.clip(freqs[-1] / np.pi * cut, 0.05, 0.9)))
    u = signal.lfilter(lb, la, rng.standard_normal(n))
    u /= np.std(u)
    y = signal.lfilter(np.r_[0.0, b], a, u)
    y = y + 0.05 * np.std(y) * rng.standard_normal(n)
    order = 2 * (n_modes - dropped)
    return IOData(u, y, ts=0.01), ARX(order, order, 1)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=20)
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--starts", type=int, default=50)
    args = ap.parse_args(argv)
    identify(*make_record("drop1", 0), rng=0)  # compile
    t_start, load0 = time.perf_counter(), os.getloadavg()[0]
    print(
        "| records | records with OE > 1 % above best | OE / best (median, worst) "
        "| spiral / best (median, worst) | spiral >= 1 % above best "
        "| spiral below OE by > 1 % | time s (OE, spiral) |"
    )
    print("|---|---|---|---|---|---|---|")
    for kind in KINDS:
        rows = []
        for seed in range(args.records):
            data, arx = make_record(kind, seed)
            est = data.split(2 / 3)[0]
            best = multistart(est, arx, args.starts)
            t0 = time.perf_counter()
            oe = identify(est, arx, method="oe").cost
            t_oe = time.perf_counter() - t0
            spiral, t_spiral = [], []
            for s in range(args.seeds):
                t0 = time.perf_counter()
                spiral.append(identify(est, arx, rng=s).cost)
                t_spiral.append(time.perf_counter() - t0)
            best = min(best, oe, *spiral)
            rows.append((oe / best, np.array(spiral) / best, t_oe, t_spiral))
        for subset, label in ((rows, "all"), ([r for r in rows if r[0] > 1.01], "")):
            if not subset:
                continue
            oe_r = np.array([r[0] for r in subset])
            sp_r = np.concatenate([r[1] for r in subset])
            below = sum(int(np.sum(r[1] < r[0] / 1.01)) for r in subset)
            name = f"{kind} ({label or 'OE trapped'})"
            print(
                f"| {name}: {len(subset)} | {int(np.sum(oe_r > 1.01))} | "
                f"{np.median(oe_r):.4f}, {oe_r.max():.4f} | {np.median(sp_r):.4f}, "
                f"{sp_r.max():.4f} | {int(np.sum(sp_r > 1.01))}/{sp_r.size} | "
                f"{below}/{sp_r.size} | {np.median([r[2] for r in subset]):.2f}, "
                f"{np.median(np.concatenate([r[3] for r in subset])):.2f} |",
                flush=True,
            )
    print(
        f"\n{time.perf_counter() - t_start:.0f} s; load average at start {load0:.2f}, "
        f"at end {os.getloadavg()[0]:.2f}"
    )


if __name__ == "__main__":
    main()
