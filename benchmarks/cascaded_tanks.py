"""The Cascaded Tanks benchmark by the grey box of
:mod:`spiralid.datasets.tanks_model`, beside ARX(2, 2, 1) by output error
and the published table.

For each seed of ``--seeds`` and each overflow of ``--overflow`` (keys of
``OVERFLOWS``: ``inflow``, the default model, ``surplus`` or ``mixed``;
``all`` for the three) it fits ``tanks_greybox(overflow=...)`` (Torricelli's exponents
fixed, 8 parameters and the 2 initial levels free) and, with
``--exponents``, ``tanks_greybox(overflow=..., exponents=True)`` (the
outflow exponents free too) to the estimation record by ``identify(est,
box, rng=seed, max_nfev=...)``, and prints the benchmark's score, the RMS
of the free-run error on the test record after its first 5 samples (the
test record runs from the initial levels estimated on the estimation
record: both records start from the same unknown state), the estimation
record's RMS, the simulations run and the seconds (compile time of the
Numba model included in the first row only; on a loaded machine, seconds
are indicative).

With ``--no-lower-top`` the models are built with ``lower_top=False`` (no
lower overflow). With ``--horizons 0.25,0.5`` the fits run ``identify(...,
horizons=(0.25, 0.5))`` (the growing horizons' shares; the default's
otherwise). With ``--held-out`` the fit sees only the estimation record's first two
thirds, and the RMS on its last third (the free run continuing over the
whole record) is printed beside the test score: that column, never the
test record, is what a variant is chosen by.

ARX(2, 2, 1) by ``oe`` runs free from rest on records centred by the
estimation record's means.

    python benchmarks/cascaded_tanks.py --seeds 0-4 --max-nfev 3000
    python benchmarks/cascaded_tanks.py --seeds 0 --overflow all --held-out
    python benchmarks/cascaded_tanks.py --seeds 0 --horizons 0.25,0.5
"""

import argparse
import time

import numpy as np
from _cli import seed_list

import spiralid as sid
from spiralid.datasets import CASCADED_TANKS_PUBLISHED, cascaded_tanks
from spiralid.datasets.tanks_model import OVERFLOWS, tanks_greybox


def rms(simulated, y, start: int = 5, stop: int | None = None) -> float:
    error = np.ravel(simulated)[start:stop] - np.ravel(y)[start:stop]
    return float(np.sqrt(np.mean(error**2)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=seed_list, default=[0, 1, 2])
    parser.add_argument("--max-nfev", type=int, default=3000)
    parser.add_argument("--exponents", action="store_true")
    parser.add_argument(
        "--overflow", choices=[*OVERFLOWS, "all"], default=next(iter(OVERFLOWS))
    )
    parser.add_argument("--held-out", action="store_true")
    parser.add_argument("--no-lower-top", action="store_true")
    parser.add_argument(
        "--horizons", type=lambda text: tuple(float(v) for v in text.split(","))
    )
    args = parser.parse_args()
    est, test = cascaded_tanks(), cascaded_tanks("test")
    # The estimation record's first two thirds, its last third held back.
    cut = round(2 * est.n / 3) if args.held_out else est.n
    overflows = list(OVERFLOWS) if args.overflow == "all" else [args.overflow]
    boxes = {}
    for overflow in overflows:
        top = {"lower_top": False} if args.no_lower_top else {}
        boxes[f"{overflow}, Torricelli"] = tanks_greybox(overflow=overflow, **top)
        if args.exponents:
            boxes[f"{overflow}, exponents"] = tanks_greybox(
                overflow=overflow, exponents=True, **top
            )
    held = "held RMS" if args.held_out else "est RMS"
    print(f"{'model':22s} {'seed':>4s} {'test RMS':>9s} {held:>8s} "
          f"{'nfev':>6s} {'s':>6s}")  # fmt: skip
    for label, box in boxes.items():
        scores = []
        for seed in args.seeds:
            start = time.perf_counter()
            options = {} if args.horizons is None else {"horizons": args.horizons}
            model = sid.identify(
                est[:cut], box, rng=seed, max_nfev=args.max_nfev, **options
            )
            seconds = time.perf_counter() - start
            scores.append(rms(model.simulate(test), test.y))
            run = model.simulate(est)
            fit = rms(run, est.y, cut) if args.held_out else rms(run, est.y)
            print(f"{label:22s} {seed:4d} {scores[-1]:9.3f} {fit:8.3f} "
                  f"{model.nfev:6d} {seconds:6.1f}", flush=True)  # fmt: skip
        print(f"{label:22s} median test RMS {np.median(scores):.3f} V, "
              f"best {min(scores):.3f}, worst {max(scores):.3f}")  # fmt: skip
    arx = sid.identify(est.detrend(), sid.ARX(2, 2, 1), method="oe")
    centred = test.detrend(like=est)
    arx_rms = rms(arx.simulate(centred) + centred.y_offset, test.y)
    print(f"\n{'ARX(2, 2, 1) by OE':60s} {arx_rms:.3f} V")
    for name, value in CASCADED_TANKS_PUBLISHED.items():
        print(f"{name:60s} {value:.3f} V")


if __name__ == "__main__":
    main()
