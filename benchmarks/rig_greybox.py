"""The rig grey box (spiralid.fms.greybox.RigGreyBox) on the nonlinear rig's
hub angle and on the DaISy robot arm, against ARX(8, 8, 0) by output error.

Parts (``--part``, default all):

- ``hub``: the hub angle of :func:`spiralid.fms.nonlinear_rig` in the paper
  experiment, estimated on the first two thirds and validated on the last
  third, for each seed (the seed draws the sensors' noise and seeds the
  search): the grey box with the flexural rigidity, hub inertia, Coulomb
  and breakaway friction free, started from the preset with the friction
  off (the amplifier's limit, 0.25 N m, known and held), against
  ARX(8, 8, 0) with two integrators by ``oe``; then each friction level's
  estimate against its 95 % interval;
- ``reduce``: what the modal truncation costs: the validation fit of the
  rig itself (at the true parameters) with 2, 3, 4, 6 and all flexible
  modes, and the seconds of one simulation;
- ``six``: the fit and the seconds of a grey box of six free parameters
  (also mass per length and damping);
- ``sensors``: the hub angle and the end accelerometer of the nonlinear
  rig's paper experiment (the encoder's quantisation, the accelerometer's
  noise and anti-aliasing filter), the grey box of ``hub`` fitted to each
  sensor alone and to both (each weighted by its noise variance), for each
  seed: each sensor's validation fit on the last third (a single-sensor
  fit's parameters run with both sensors), the seconds, and each free
  field's estimate and 95 % interval against the rig's truth;
- ``arm``: the DaISy robot arm (``datasets.robot_arm()``, detrended), the
  rig with its geometry free (bounds a factor 100 either side of the
  preset: the arm is not the Sheffield rig), run from rest, against
  ARX(8, 8, 0) by ``oe``; with the acceleration as recorded and with its
  sign flipped, the rig without gain or initial state (the record
  states no sign convention); ``benchmarks/daisy_greybox.py`` adds both
  and a start from the record's modes.

Times are wall-clock seconds on the machine that runs this.

    python benchmarks/rig_greybox.py --seeds 5
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from spiralid.datasets import robot_arm
from spiralid.fms import FlexibleManipulator, Sensors, nonlinear_rig, paper_experiment
from spiralid.fms.greybox import RigGreyBox
from spiralid.sysid import ARX, IOData, Parameter, identify, validate

FREE = ["flexural_rigidity", "hub_inertia", "coulomb_friction", "static_friction"]
SIX = [*FREE[:2], "mass_per_length", "damping_ratio", *FREE[2:]]
GEOMETRY = [
    "length",
    "flexural_rigidity",
    "mass_per_length",
    "hub_inertia",
    "damping_ratio",
]
MODES = 4
SENSORS = ("hub_angle", "end_acceleration")
# The start: the preset with the friction off and the amplifier's limit
# known (paper pulses of 0.3 N m are clipped to 0.25 N m).
START = nonlinear_rig(coulomb_friction=0.0, static_friction=0.0)


def _hub_record(seed: int):
    rec = paper_experiment().run(rig=nonlinear_rig(), rng=seed)
    return rec.iodata("hub_angle").split(2 / 3)


def _fit(model, est, val) -> float:
    return float(validate(model, val, warmup=est).fit_percent)


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def part_hub(seeds: list[int], n_modes: int = MODES) -> None:
    print("## Nonlinear rig, hub angle, validation on the last third")
    print("| seed | grey box % | s | ARX oe % |")
    print("|---|---|---|---|")
    truth = nonlinear_rig()
    friction = []
    for seed in seeds:
        est, val = _hub_record(seed)
        box = RigGreyBox(FREE, START, n_modes=n_modes)
        t0 = time.perf_counter()
        model = identify(est, box, method="spiral", rng=seed)
        secs = time.perf_counter() - t0
        arx = identify(est, ARX(8, 8, 0), method="oe", integrator=2, rng=seed)
        print(
            f"| {seed} | {_fit(model, est, val):.2f} | {secs:.0f} | "
            f"{_fit(arx, est, val):.2f} |",
            flush=True,
        )
        friction.append(model)
    print("\n## Friction levels against their 95 % intervals")
    print("| seed | field | truth | estimate | 95 % interval |")
    print("|---|---|---|---|---|")
    for seed, model in zip(seeds, friction, strict=True):
        for name in FREE[2:]:
            i = model.structure.names.index(name)
            low, high = model.intervals[i]
            interval = f"[{low:.4g}, {high:.4g}]" if np.isfinite(low) else "none"
            print(
                f"| {seed} | {name} | {getattr(truth, name):g} | "
                f"{model.values[i]:.4g} | {interval} |",
                flush=True,
            )


def part_reduce() -> None:
    print("\n## Modal truncation at the true parameters (seed 0)")
    print("| flexible modes | states | validation fit % | s per run |")
    print("|---|---|---|---|")
    est, val = _hub_record(0)
    data = IOData(
        np.r_[est.u, val.u], np.r_[est.y, val.y], ts=est.ts, output_name="hub_angle"
    )
    for n_modes in (2, 3, 4, 6, None):
        box = RigGreyBox(FREE, nonlinear_rig(), n_modes=n_modes)
        values = box.initial_values
        box.simulate(values, data.u, data.ts)  # compiled and cached
        runs = 3
        t0 = time.perf_counter()
        for k in range(runs):
            y = box.simulate(values * (1 + 1e-9 * k), data.u, data.ts)
        secs = time.perf_counter() - t0
        e = val.y - y[est.n :]
        fit = 100 * (1 - np.linalg.norm(e) / np.linalg.norm(val.y - val.y.mean()))
        label = "all 20" if n_modes is None else str(n_modes)
        print(f"| {label} | {box.n_states} | {fit:.2f} | {secs / runs:.3f} |")


def part_six(seed: int = 0, n_modes: int = MODES) -> None:
    print("\n## Six free parameters (seed 0)")
    est, val = _hub_record(seed)
    box = RigGreyBox(SIX, START, n_modes=n_modes)
    model, secs = _timed(lambda: identify(est, box, method="spiral", rng=seed))
    print(
        f"validation fit {_fit(model, est, val):.2f} %, {secs:.0f} s, "
        f"{model.nfev} simulations"
    )
    print(model.summary())


def _both_fits(values, data: IOData, n_est: int) -> list[float]:
    """Each sensor's fit % on the validation part of `data` (the record's
    two sensors) of the rig at `values`, run from rest over the whole
    record (the validation from the state the estimation part left)."""
    box = RigGreyBox(FREE, START, output=SENSORS, n_modes=MODES)
    y = box.simulate(values, data.u, data.ts)[n_est:]
    ref = data.y[n_est:]
    spread = np.linalg.norm(ref - ref.mean(axis=0), axis=0)
    return list(100 * (1 - np.linalg.norm(ref - y, axis=0) / spread))


def part_sensors(seeds: list[int]) -> None:
    print("\n## Two sensors: hub angle and end acceleration, validation on the")
    print("last third")
    print("| seed | fitted to | hub % | accel. % | s |")
    print("|---|---|---|---|---|")
    truth = nonlinear_rig()
    rows = []
    for seed in seeds:
        rec = paper_experiment().run(rig=truth, rng=seed)
        data = rec.iodata(list(SENSORS))
        est = data.split(2 / 3)[0]
        for fitted in (*SENSORS, SENSORS):
            one = est.select_outputs(list(fitted)) if fitted == SENSORS else None
            box = RigGreyBox(FREE, START, output=fitted, n_modes=MODES)
            d = est.output(fitted) if one is None else one
            model, secs = _timed(
                lambda b=box, d=d, s=seed: identify(d, b, method="spiral", rng=s)
            )
            hub, acc = _both_fits(model.values, data, est.n)
            label = "both" if fitted == SENSORS else fitted
            print(
                f"| {seed} | {label} | {hub:.2f} | {acc:.2f} | {secs:.0f} |", flush=True
            )
            rows.append((seed, label, model))
    print("\n## Two sensors: each field against its 95 % interval")
    print("| seed | fitted to | field | truth | estimate | 95 % interval |")
    print("|---|---|---|---|---|---|")
    for seed, label, model in rows:
        for i, name in enumerate(model.structure.names):
            low, high = model.intervals[i]
            interval = f"[{low:.4g}, {high:.4g}]" if np.isfinite(low) else "none"
            print(
                f"| {seed} | {label} | {name} | {getattr(truth, name):.4g} | "
                f"{model.values[i]:.4g} | {interval} |",
                flush=True,
            )


def part_arm(seed: int = 0) -> None:
    print("\n## DaISy robot arm, validation on the last third")
    data = robot_arm().detrend()
    rig = FlexibleManipulator()
    wide = [
        Parameter(p.name, p.value, (p.value / 100, p.value * 100), p.unit)
        for p in RigGreyBox(GEOMETRY[:4], rig).parameters
    ]
    wide.append(Parameter("damping_ratio", 0.02, (0.001, 0.3)))
    box = RigGreyBox(
        wide, rig, output="end_acceleration", sensors=Sensors.ideal(), n_modes=MODES
    )
    est, val = data.split(2 / 3)
    arx = identify(est, ARX(8, 8, 0), method="oe", rng=seed)
    print(f"ARX(8, 8, 0) by oe {_fit(arx, est, val):.2f} %")
    for sign in (1.0, -1.0):
        signed = IOData(data.u, sign * data.y, ts=data.ts)
        est, val = signed.split(2 / 3)
        model, secs = _timed(lambda e=est: identify(e, box, method="spiral", rng=seed))
        print(
            f"rig grey box, sign {sign:+g}: {_fit(model, est, val):.2f} % "
            f"({secs:.0f} s)"
        )
        print(model.summary())
        print(box.modes_beside(model.values))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument(
        "--modes",
        type=int,
        default=MODES,
        help="flexible modes of the grey box in the hub and six parts",
    )
    ap.add_argument(
        "--part",
        choices=["all", "hub", "reduce", "six", "sensors", "arm"],
        default="all",
    )
    args = ap.parse_args()
    if args.part in ("all", "hub"):
        part_hub(list(range(args.seeds)), args.modes)
    if args.part in ("all", "reduce"):
        part_reduce()
    if args.part in ("all", "six"):
        part_six(n_modes=args.modes)
    if args.part in ("all", "sensors"):
        part_sensors(list(range(args.seeds)))
    if args.part in ("all", "arm"):
        part_arm()


if __name__ == "__main__":
    main()
