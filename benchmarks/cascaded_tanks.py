"""The Cascaded Tanks benchmark by the grey box of
:mod:`spiralid.datasets.tanks_model`, beside ARX(2, 2, 1) by output error
and the published table.

For each seed of ``--seeds`` it fits ``tanks_greybox()`` (Torricelli's
exponents fixed, 8 parameters and the 2 initial levels free) and, with
``--exponents``, ``tanks_greybox(exponents=True)`` (the outflow exponents
free too) to the estimation record by ``identify(est, box, rng=seed,
max_nfev=...)``, and prints the benchmark's score, the RMS of the free-run
error on the test record after its first 5 samples (the test record runs
from the initial levels estimated on the estimation record: both records
start from the same unknown state), the estimation record's RMS, the
simulations run and the seconds (compile time of the Numba model included
in the first row only; on a loaded machine, seconds are indicative).

ARX(2, 2, 1) by ``oe`` runs free from rest on records centred by the
estimation record's means.

    python benchmarks/cascaded_tanks.py --seeds 0-4 --max-nfev 3000
"""

import argparse
import time

import numpy as np
from _cli import seed_list

import spiralid as sid
from spiralid.datasets import CASCADED_TANKS_PUBLISHED, cascaded_tanks
from spiralid.datasets.tanks_model import tanks_greybox


def rms(simulated, record) -> float:
    return float(np.sqrt(np.mean((simulated[5:] - record.y[5:]) ** 2)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=seed_list, default=[0, 1, 2])
    parser.add_argument("--max-nfev", type=int, default=3000)
    parser.add_argument("--exponents", action="store_true")
    args = parser.parse_args()
    est, test = cascaded_tanks(), cascaded_tanks("test")
    boxes = {"Torricelli": tanks_greybox()}
    if args.exponents:
        boxes["free exponents"] = tanks_greybox(exponents=True)
    print(f"{'model':16s} {'seed':>4s} {'test RMS':>9s} {'est RMS':>8s} "
          f"{'nfev':>6s} {'s':>6s}")  # fmt: skip
    for label, box in boxes.items():
        scores = []
        for seed in args.seeds:
            start = time.perf_counter()
            model = sid.identify(est, box, rng=seed, max_nfev=args.max_nfev)
            seconds = time.perf_counter() - start
            scores.append(rms(model.simulate(test), test))
            print(f"{label:16s} {seed:4d} {scores[-1]:9.3f} "
                  f"{rms(model.simulate(est), est):8.3f} {model.nfev:6d} "
                  f"{seconds:6.1f}", flush=True)  # fmt: skip
        print(f"{label:16s} median test RMS {np.median(scores):.3f} V, "
              f"best {min(scores):.3f}, worst {max(scores):.3f}")  # fmt: skip
    arx = sid.identify(est.detrend(), sid.ARX(2, 2, 1), method="oe")
    centred = test.detrend(like=est)
    arx_rms = rms(arx.simulate(centred) + centred.y_offset, test)
    print(f"\n{'ARX(2, 2, 1) by OE':60s} {arx_rms:.3f} V")
    for name, value in CASCADED_TANKS_PUBLISHED.items():
        print(f"{name:60s} {value:.3f} V")


if __name__ == "__main__":
    main()
