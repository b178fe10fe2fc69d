"""Every output of the simulated rig, with and without a known integrator.

The rig's hub angle integrates the hub velocity (a pole at z = 1): a model
that must find that pole itself stops at its stability bound. With
``identify(integrator=True)`` the pole is known and the method estimates the
others. Prints, per output and structure: estimation cost (eq. 2), validation
fit % (free run over the whole record, scored on the last third) and wall
time, for output error and the recommended ``spiral`` method (seed 0), with
and without the integrator, and the machine load.

Run: ``python benchmarks/rig_outputs.py``.
"""

import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from spiralid.fms import FlexibleManipulator, paper_experiment
from spiralid.fms.rig import _OUTPUTS
from spiralid.sysid import ARX, identify, validate


def main() -> None:
    record = paper_experiment().run(FlexibleManipulator(), rng=0)
    identify(record.iodata().split(2 / 3)[0], ARX(2, 2, 0), rng=0)  # compile
    head = "output | structure | method | integrator | cost | validation fit % | time s"
    print(f"| {head} |")
    print("|---|---|---|---|---|---|---|")
    for name in _OUTPUTS:
        est, val = record.iodata(name).split(2 / 3)
        for arx in (ARX(4, 4, 1), ARX(8, 8, 0)):
            for method in ("oe", "spiral"):
                for integrator in (False, True):
                    t0 = time.perf_counter()
                    fit = identify(
                        est, arx, method=method, rng=0, integrator=integrator
                    )
                    seconds = time.perf_counter() - t0
                    fit_val = validate(fit, val, warmup=est).fit_percent
                    known = "yes" if integrator else "no"
                    print(
                        f"| {name} | {arx} | {method} | {known} | {fit.cost:.4g} "
                        f"| {fit_val:.1f} | {seconds:.2f} |",
                        flush=True,
                    )
    print(f"\nload average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
