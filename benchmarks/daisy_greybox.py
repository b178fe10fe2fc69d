"""The rig grey box (spiralid.fms.RigGreyBox) on DaISy's flexible robot arm,
beside ARX(8, 8, 0) by output error.

``datasets.robot_arm()`` (detrended; 0.01 s assumed), estimated on the first
two thirds, validated on the last third after a warm-up over the first two
(as every model's validation here). The rig's end acceleration with two
flexible modes (the arm's black boxes show two), ideal sensors, free:
flexural rigidity, hub inertia, payload mass and inertia, damping ratio, a
signed output gain (the record's units are unstated) and the modal initial
state (the record starts in motion); the length and the mass per length
are held (with the gain free, a common scale of every mass and stiffness is
invisible in the record). Rows:

- ``preset``: from the Sheffield preset (the gain and the state by least
  squares at the preset);
- ``modes``: from :func:`spiralid.fms.greybox_start.rig_start_from_modes`
  on the ARX fit's modes (the start itself, then ``oe``'s polish and
  ``spiral``'s search from it);
- ``ARX(4, 5, 0)`` by ``oe``: a black box with the same two modes and free
  residues, what a two-mode linear model can reach.

Times are wall-clock seconds on the machine that runs this (a shared
machine: compare, do not quote as absolute).

    python benchmarks/daisy_greybox.py
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from spiralid.datasets import robot_arm
from spiralid.fms import FlexibleManipulator, Sensors
from spiralid.fms.greybox import GAIN, RigGreyBox
from spiralid.fms.greybox_start import rig_start_from_modes
from spiralid.sysid import ARX, Parameter, identify, validate
from spiralid.sysid.models.greybox_model import LinearGreyBoxModel

MODES = 2


def _fit(model, est, val) -> float:
    return float(validate(model, val, warmup=est).fit_percent)


def _box() -> RigGreyBox:
    """The rig's free fields with bounds a factor 100 around the preset
    (the payload from a thousandth to a hundred times the beam's)."""
    rig = FlexibleManipulator()
    beam = rig.density * rig.area * rig.length
    free = [
        Parameter("flexural_rigidity", rig.flexural_rigidity,
                  (rig.flexural_rigidity / 100, rig.flexural_rigidity * 100), "N m^2"),
        Parameter("hub_inertia", rig.hub_inertia,
                  (rig.hub_inertia / 100, rig.hub_inertia * 100), "kg m^2"),
        Parameter("payload_mass", beam, (beam / 1e3, beam * 100), "kg"),
        Parameter("payload_inertia", beam * rig.length**2 / 3,
                  (beam * rig.length**2 / 3e3, beam * rig.length**2 * 30), "kg m^2"),
        Parameter("damping_ratio", 0.02, (0.001, 0.3)),
    ]  # fmt: skip
    n_states = 2 * (MODES + 1)
    x0 = [Parameter(f"s{i}", 0.0, (-1.0, 1.0)) for i in range(n_states)]
    return RigGreyBox(
        free,
        rig,
        output="end_acceleration",
        sensors=Sensors.ideal(),
        n_modes=MODES,
        output_gain=Parameter(GAIN, 1.0, (-10.0, 10.0)),
        x0=x0,
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    seed = ap.parse_args().seed
    data = robot_arm().detrend()
    est, val = data.split(2 / 3)
    print("## DaISy robot arm, validation on the last third (warm-up: the rest)")
    print("| model | fit % | s |")
    print("|---|---|---|")
    t0 = time.perf_counter()
    arx = identify(est, ARX(8, 8, 0), method="oe", rng=seed)
    print(f"| ARX(8, 8, 0) oe | {_fit(arx, est, val):.2f} | "
          f"{time.perf_counter() - t0:.0f} |", flush=True)  # fmt: skip
    t0 = time.perf_counter()
    two = identify(est, ARX(4, 5, 0), method="oe", rng=seed)
    print(f"| ARX(4, 5, 0) oe | {_fit(two, est, val):.2f} | "
          f"{time.perf_counter() - t0:.0f} |", flush=True)  # fmt: skip
    box = _box()
    table = arx.modes
    keep = ~table.spurious
    starts = {
        "preset": rig_start_from_modes(box, box.rig.modes(MODES), est),
        "modes": rig_start_from_modes(box, arx, est, rng=seed),
    }
    fitted = {}
    for label, start in starts.items():
        at_start = LinearGreyBoxModel(start, start.initial_values, est.ts, "start")
        print(f"| rig, {label} start (no fit) | "
              f"{_fit(at_start, est, val):.2f} | - |", flush=True)  # fmt: skip
        for method in ("oe", "spiral"):
            t0 = time.perf_counter()
            model = identify(est, start, method=method, rng=seed)
            secs = time.perf_counter() - t0
            print(f"| rig, {label} start, {method} | {_fit(model, est, val):.2f} | "
                  f"{secs:.0f} |", flush=True)  # fmt: skip
            fitted[label, method] = model
    pairs = zip(table.frequency[keep], table.damping[keep], strict=True)
    print("\nARX(8, 8, 0)'s modes (Hz, damping):",
          ", ".join(f"{f:.3f} ({z:.4f})" for f, z in pairs))  # fmt: skip
    best = max(fitted.values(), key=lambda m: _fit(m, est, val))
    print("\nBest rig fit:")
    print(best.summary())
    print(best.structure.modes_beside(best.values, MODES + 1))


if __name__ == "__main__":
    np.set_printoptions(precision=4)
    main()
