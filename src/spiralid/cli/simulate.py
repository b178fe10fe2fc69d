"""``spiralid simulate``: drive the simulated rig and write a record."""

from __future__ import annotations

from pathlib import Path

from .errors import UsageError
from .options import (
    _add_output_options,
    _add_seed_option,
    _command,
    _nonneg_float,
    _positive_float,
    _progress,
)


def run(args, argv: list[str]) -> int:
    suffix = Path(args.out).suffix.lower()
    if suffix not in (".csv", ".npz"):
        raise UsageError(f"--out {args.out!r} must end in .csv or .npz")
    if args.width is not None and args.signal not in _PULSES:
        raise UsageError(
            f"--width applies to --signal {' and '.join(_PULSES)}; --signal "
            f"{args.signal} has no pulses"
        )
    from spiralid.outputs.atomic import OutputFile

    with _progress(args) as progress, OutputFile(args.out, args.force) as target:
        progress.phase("simulation", f"simulating {args.duration:g} s of the rig")
        rec, rig = _simulate_record(args)
        progress.phase("writing", f"writing {args.out}")
        _write_record(rec, target.path, suffix)
        target.commit()
    if not args.quiet:
        print(
            f"wrote {args.out} ({rec.u.size} samples at {args.fs:g} Hz; rig modes "
            + ", ".join(f"{f:.2f}" for f in rig.modes(3))
            + " Hz)"
        )
    return 0


# The torque (N m) of each signal when --amplitude is not given: the paper
# experiment's pulses, and a tenth of a newton metre for the broadband ones.
_AMPLITUDES = {"paper": 0.3, "bang-bang": 0.3, "prbs": 0.1, "chirp": 0.1}
# The signals made of pulses, which --width shapes.
_PULSES = ("paper", "bang-bang")


def _simulate_record(args):
    from spiralid.fms import (
        Experiment,
        FlexibleManipulator,
        Sensors,
        bang_bang,
        chirp,
        nonlinear_rig,
        prbs,
    )

    nonlinear = {
        name: getattr(args, name)
        for name in ("coulomb_friction", "static_friction", "torque_limit")
        if getattr(args, name) is not None
    }
    if args.nonlinear:
        rig = nonlinear_rig(payload_mass=args.payload, **nonlinear)
    else:
        rig = FlexibleManipulator(payload_mass=args.payload, **nonlinear)
    fs = args.fs
    paper = Experiment()
    amp = _AMPLITUDES[args.signal] if args.amplitude is None else args.amplitude
    if args.signal == "paper":
        # One pulse per period, as many as the duration holds (even count: the
        # hub returns to where it started).
        n_pulses = max(2 * int(args.duration // (2 * paper.period)), 1)
        exp = Experiment(
            amplitude=amp,
            width=paper.width if args.width is None else args.width,
            duration=args.duration,
            fs=fs,
            n_pulses=n_pulses,
        )
        torque = exp.torque()
    elif args.signal == "bang-bang":
        width = paper.width if args.width is None else args.width
        torque = bang_bang(amp, width, paper.start, args.duration, fs)
    elif args.signal == "prbs":
        torque = prbs(amp, args.duration, fs)
    else:
        torque = chirp(amp, 1.0, min(100.0, fs / 2), args.duration, fs)
    sensors = Sensors(accel_noise=args.accel_noise, tach_noise=args.tach_noise)
    rec = rig.simulate(torque, fs=fs, rng=args.seed, sensors=sensors)
    return rec, rig


def _write_record(rec, path: Path, suffix: str) -> None:
    import numpy as np

    columns = {
        "time_s": rec.t,
        "torque_Nm": rec.u,
        "hub_angle_rad": rec.hub_angle,
        "hub_velocity_rad_s": rec.hub_velocity,
        "end_acceleration_m_s2": rec.end_acceleration,
    }
    if suffix == ".npz":
        np.savez(
            path,
            ts=np.float64(rec.ts),
            u=rec.u,
            y=rec.end_acceleration,
            **columns,
        )
    else:
        np.savetxt(
            path,
            np.column_stack(list(columns.values())),
            delimiter=",",
            header=",".join(columns),
            comments="",
            fmt="%.10g",
        )


_DESCRIPTION = (
    "Drive the finite-element flexible manipulator rig with a torque signal "
    "and write time, torque, hub angle, hub velocity and end-point "
    "acceleration (CSV header carries the units)."
)


def add_parser(sub) -> None:
    p = _command(
        sub,
        "simulate",
        "simulate the flexible manipulator rig and write a CSV or NPZ",
        _DESCRIPTION,
        run,
    )
    p.add_argument(
        "--signal",
        choices=["paper", "bang-bang", "prbs", "chirp"],
        default="paper",
        help="torque input: 'paper' is the reproduction's train of bang-bang "
        "pulses (one per second), 'bang-bang' a single pulse pair",
    )
    p.add_argument(
        "--amplitude",
        type=float,
        default=None,
        help="torque (N m); default "
        + ", ".join(f"{v:g} for {k}" for k, v in _AMPLITUDES.items()),
    )
    p.add_argument(
        "--width",
        type=_positive_float,
        default=None,
        help="bang-bang pulse width (s); default 0.04",
    )
    p.add_argument(
        "--duration", type=_positive_float, default=6.0, help="record length (s)"
    )
    p.add_argument("--fs", type=_positive_float, default=500.0, help="sample rate (Hz)")
    p.add_argument("--payload", type=float, default=0.0, help="tip payload (kg)")
    p.add_argument(
        "--accel-noise", type=float, default=1.0, help="accelerometer noise std (m/s^2)"
    )
    p.add_argument(
        "--tach-noise", type=float, default=0.01, help="tachometer noise std (rad/s)"
    )
    p.add_argument(
        "--nonlinear",
        action="store_true",
        help="the rig with hub friction and torque saturation "
        "(spiralid.fms.nonlinear_rig: Coulomb 0.02 N m, breakaway 0.03 N m, "
        "limit 0.25 N m); the three options below override its values",
    )
    p.add_argument(
        "--coulomb-friction",
        type=_nonneg_float,
        default=None,
        help="hub Coulomb friction (N m); default 0 (off)",
    )
    p.add_argument(
        "--static-friction",
        type=_nonneg_float,
        default=None,
        help="hub breakaway torque (N m), Stribeck law above Coulomb; default 0",
    )
    p.add_argument(
        "--torque-limit",
        type=_positive_float,
        default=None,
        help="amplifier saturation (N m); default none",
    )
    _add_seed_option(p, "noise seed")
    _add_output_options(p, "rig.csv", "output file, .csv or .npz", "overwrite --out")
