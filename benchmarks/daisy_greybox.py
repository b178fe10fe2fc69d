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
  residues, what a two-mode linear model can reach;
- ``rig's form``: the best model of the rig's form whatever its fields,
  ``a0 + sum_i a_i s^2 / (s^2 + 2 z_i w_i s + w_i^2)`` over two modes (a
  hub torque's acceleration in modal coordinates: one real residue per
  mode, its phase set by the mode), with the residues ``a``, the initial
  state and even each mode's damping free: the residues and the state by
  least squares, the modes by Levenberg-Marquardt from the ARX's.

``--input-delay`` also frees the rig's ``input_delay`` (s, within 0.009 s
either way, started at minus half a sample: the lag of a zero-order hold
behind a measured input).

``--damping rayleigh`` replaces the one damping ratio (held at 0) by the
rig's Rayleigh damping, ``mass_damping`` and ``stiffness_damping`` free
(each mode its own ratio, ``alpha / (2 w_k) + beta w_k / 2``: with two
modes, any two ratios within a factor ``w2 / w1`` of each other), started
where they give the ARX fit's two modes their damping and bounded by a
ratio of 0.3 at the first mode.

``--hub-friction`` also frees ``hub_friction`` (the rigid mode's viscous
damping; from 1e-4 N m s/rad, up to ten times the rig's inertia per
second).

``--accelerometer X`` reads the record's acceleration at a fraction ``X``
of the beam's length (an accelerometer's position, a sensor of
``Sensors.ideal(acceleration_at=(X,))``) rather than at the end; choose
``X`` on the estimation record's held-back part (``--scan``), not on the
validation third.

``--scan X1,X2,...`` fits the rig (``oe``, from the ARX's modes) on the
first three quarters of the estimation record for each accelerometer
position (1 the end) and prints the fit on its last quarter (warm-up: the
three quarters): the positions' choice, the validation third unseen.

``--bound-only`` prints the black boxes and that bound, without the rig;
``--starts modes`` only the rig's start from the ARX's modes.

Times are wall-clock seconds on the machine that runs this (a shared
machine: compare, do not quote as absolute).

    python benchmarks/daisy_greybox.py
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy import signal
from scipy.optimize import least_squares

from spiralid.datasets import robot_arm
from spiralid.fms import FlexibleManipulator, Sensors
from spiralid.fms.greybox import DELAY, GAIN, RigGreyBox
from spiralid.fms.greybox_start import rig_start_from_modes
from spiralid.sysid import ARX, Parameter, identify, validate
from spiralid.sysid.models.greybox_model import LinearGreyBoxModel

MODES = 2


def _fit(model, est, val) -> float:
    return float(validate(model, val, warmup=est).fit_percent)


def _form_columns(p, u: np.ndarray, ts: float) -> np.ndarray:
    """The rig form's regressors at the modes `p` (log Hz, log damping per
    mode): the feedthrough, each mode's forced response and its two free
    responses."""
    cols = [u]
    for f, z in np.exp(np.reshape(p, (-1, 2))):
        w = 2 * np.pi * f
        b, a, _ = signal.cont2discrete(([1, 0, 0], [1, 2 * z * w, w * w]), ts)
        cols.append(signal.lfilter(np.ravel(b), a, u))
        for k in range(2):
            cols.append(signal.lfilter([1.0], a, np.eye(1, u.size, k)[0]))
    return np.column_stack(cols)


def _form_bound(est, val, table) -> float:
    """The validation fit of the best model of the rig's form (see the
    module docstring), started at `table`'s modes not marked spurious."""
    keep = ~table.spurious
    p0 = np.log(np.column_stack([table.frequency[keep], table.damping[keep]]))

    def coef(p):
        cols = _form_columns(p, est.u, est.ts)
        return cols, np.linalg.lstsq(cols, est.y, rcond=None)[0]

    def residual(p):
        cols, c = coef(p)
        return est.y - cols @ c

    p = least_squares(residual, p0.ravel(), diff_step=1e-7).x
    whole = _form_columns(p, np.r_[est.u, val.u], est.ts) @ coef(p)[1]
    e = val.y - whole[est.n :]
    return float(100 * (1 - np.linalg.norm(e) / np.linalg.norm(val.y - val.y.mean())))


def _rayleigh(table) -> list[Parameter]:
    """``mass_damping`` and ``stiffness_damping``, bounded by a ratio of 0.3
    at `table`'s first mode (``rig_start_from_modes`` starts them where
    they give the table's modes their damping)."""
    w1 = 2 * np.pi * table.frequency[~table.spurious][0]
    return [
        Parameter("mass_damping", 0.0, (0.0, 0.6 * w1), "1/s"),
        Parameter("stiffness_damping", 0.0, (0.0, 0.6 / w1), "s"),
    ]


def _box(
    delay: bool = False, damping=None, at: float | None = None, hub: bool = False
) -> RigGreyBox:
    """The rig's free fields with bounds a factor 100 around the preset
    (the payload from a thousandth to a hundred times the beam's); with
    `damping` (Rayleigh's two Parameters) those instead of the one damping
    ratio, held at 0; the acceleration at the end or, with `at`, at that
    fraction of the length; with `hub`, the hub's viscous friction free."""
    rig = FlexibleManipulator(damping_ratio=0.0 if damping else 0.02)
    beam = rig.density * rig.area * rig.length
    free = [
        Parameter("flexural_rigidity", rig.flexural_rigidity,
                  (rig.flexural_rigidity / 100, rig.flexural_rigidity * 100), "N m^2"),
        Parameter("hub_inertia", rig.hub_inertia,
                  (rig.hub_inertia / 100, rig.hub_inertia * 100), "kg m^2"),
        Parameter("payload_mass", beam, (beam / 1e3, beam * 100), "kg"),
        Parameter("payload_inertia", beam * rig.length**2 / 3,
                  (beam * rig.length**2 / 3e3, beam * rig.length**2 * 30), "kg m^2"),
    ]  # fmt: skip
    free += damping or [Parameter("damping_ratio", 0.02, (0.001, 0.3))]
    if hub:
        high = 10 * rig.total_inertia
        free.append(Parameter("hub_friction", 1e-4, (0.0, high), "N m s/rad"))
    if delay:
        free.append(Parameter(DELAY, -0.005, (-0.009, 0.009), "s"))
    n_states = 2 * (MODES + 1)
    x0 = [Parameter(f"s{i}", 0.0, (-1.0, 1.0)) for i in range(n_states)]
    sensors = Sensors.ideal(acceleration_at=() if at is None else (at,))
    return RigGreyBox(
        free,
        rig,
        output="end_acceleration" if at is None else sensors.positional_names[0],
        sensors=sensors,
        n_modes=MODES,
        output_gain=Parameter(GAIN, 1.0, (-10.0, 10.0)),
        x0=x0,
    )


def _scan(est, args, rayleigh) -> None:
    """The accelerometer's position chosen on the estimation record alone:
    fitted on its first three quarters, scored on its last quarter."""
    part, held = est.split(3 / 4)
    arx = identify(part, ARX(8, 8, 0), method="oe", rng=args.seed)
    print("\n| accelerometer at | fit % (3/4) | held-back % (1/4) |")
    print("|---|---|---|")
    for x in map(float, args.scan.split(",")):
        at = None if x == 1.0 else x
        box = _box(args.input_delay, rayleigh, at, args.hub_friction)
        start = rig_start_from_modes(box, arx, part, rng=args.seed)
        model = identify(part, start, method="oe", rng=args.seed)
        print(f"| {x:g} | {validate(model, part).fit_percent:.2f} | "
              f"{_fit(model, part, held):.2f} |", flush=True)  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--bound-only", action="store_true")
    ap.add_argument("--input-delay", action="store_true")
    ap.add_argument("--damping", choices=("ratio", "rayleigh"), default="ratio")
    ap.add_argument(
        "--starts", default="preset,modes", help="the rig's starts, comma-separated"
    )
    ap.add_argument("--methods", default="oe,spiral", help="comma-separated")
    ap.add_argument("--accelerometer", type=float, default=None)
    ap.add_argument("--hub-friction", action="store_true")
    ap.add_argument("--scan", default=None, help="accelerometer positions")
    args = ap.parse_args()
    seed = args.seed
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
    table = arx.modes
    print(f"| rig's form, any fields | {_form_bound(est, val, table):.2f} | - |")
    if args.bound_only:
        return
    rayleigh = _rayleigh(table) if args.damping == "rayleigh" else None
    if args.scan:
        _scan(est, args, rayleigh)
        return
    box = _box(args.input_delay, rayleigh, args.accelerometer, args.hub_friction)
    keep = ~table.spurious
    modes = {"preset": box.rig.modes(MODES), "modes": arx}
    starts = {
        label: rig_start_from_modes(box, modes[label], est, rng=seed)
        for label in args.starts.split(",")
    }
    fitted = {}
    for label, start in starts.items():
        at_start = LinearGreyBoxModel(start, start.initial_values, est.ts, "start")
        print(f"| rig, {label} start (no fit) | "
              f"{_fit(at_start, est, val):.2f} | - |", flush=True)  # fmt: skip
        for method in args.methods.split(","):
            t0, c0 = time.perf_counter(), time.process_time()
            model = identify(est, start, method=method, rng=seed)
            secs, cpu = time.perf_counter() - t0, time.process_time() - c0
            print(f"| rig, {label} start, {method} | {_fit(model, est, val):.2f} | "
                  f"{secs:.0f} (cpu {cpu:.0f}) |", flush=True)  # fmt: skip
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
