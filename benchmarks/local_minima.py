"""Is the spiral's global part worth its evaluations? Records whose output-
error criterion has several local minima, against an independent multistart.

Records (seeded, ``--records`` of each kind): a random lightly damped system
of order 4 or 6 (two or three modes at random frequencies, pole radii
0.90-0.99, a random numerator), driven by

- ``lowpass``: white noise low-pass filtered (4th-order Butterworth) below
  the highest mode, so some modes are weakly excited;
- ``burst``: a windowed noise burst followed by a quiet tail;

with output noise at 5 % of the output's RMS, 900 samples, ARX(n, n, 1) of
the true order. On each record: the best estimation cost a 50-start
multistart finds (least squares, Steiglitz-McBride and 48 random stable
denominators, each polished by output error's local method:
``rig_outputs.multistart``); output error (two starts); and the recommended
``spiral`` method, seeds 0-4. Prints per kind: the records on which OE is
more than 1 % above the multistart's best (it stopped in a local minimum),
and on those and on all records the median and worst ratio of each method's
cost to the best; the median time.

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

KINDS = ("lowpass", "burst")


def make_record(kind: str, seed: int) -> tuple[IOData, ARX]:
    rng = np.random.default_rng(seed)
    n_modes = int(rng.integers(2, 4))
    freqs = np.sort(rng.uniform(0.08, 0.9, n_modes)) * np.pi
    radii = rng.uniform(0.90, 0.99, n_modes)
    poles = np.concatenate([radii * np.exp(1j * freqs), radii * np.exp(-1j * freqs)])
    a = np.real(np.poly(poles))
    b = rng.standard_normal(2 * n_modes)
    n = 900
    if kind == "lowpass":
        cut = float(np.clip(freqs[-1] / np.pi * 0.6, 0.05, 0.9))
        lb, la = signal.butter(4, cut)
        u = signal.lfilter(lb, la, rng.standard_normal(n))
        u /= np.std(u)
    else:
        u = np.zeros(n)
        u[30:480] = rng.standard_normal(450) * np.hanning(450)
    y = signal.lfilter(np.r_[0.0, b], a, u)
    y = y + 0.05 * np.std(y) * rng.standard_normal(n)
    return IOData(u, y, ts=0.01), ARX(2 * n_modes, 2 * n_modes, 1)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=10)
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--starts", type=int, default=50)
    args = ap.parse_args(argv)
    identify(*make_record("burst", 0), rng=0)  # compile
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
