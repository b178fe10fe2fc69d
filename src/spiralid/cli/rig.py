"""``spiralid identify --model rig``: the flexible manipulator's physical
parameters (:class:`spiralid.fms.greybox.RigGreyBox`) fitted to a record of
one or several of its sensors, validated on the rest of the record."""

from __future__ import annotations

import argparse

from .errors import UsageError
from .options import (
    _detrended,
    _listing,
    _load_data,
    _open_folder,
    _positive_int,
    _progress,
    _save_figures,
)

# The flags of --model rig alone.
RIG_FLAGS = ("--free", "--sensor", "--modes", "--rig")


def _free_fields(text: str) -> list[str]:
    """--free: field names separated by commas, each of the one list
    (spiralid.choices.RIG_PARAMETERS)."""
    from spiralid.choices import RIG_PARAMETERS

    names = [part.strip() for part in text.split(",") if part.strip()]
    unknown = [n for n in names if n not in RIG_PARAMETERS]
    if not names or unknown:
        raise argparse.ArgumentTypeError(
            f"unknown field {', '.join(unknown) or repr(text)}; the rig's fields: "
            f"{', '.join(RIG_PARAMETERS)}"
        )
    return names


def add_rig_options(p: argparse.ArgumentParser) -> None:
    """--free, --sensor, --modes and --rig (for --model rig)."""
    p.add_argument(
        "--free",
        type=_free_fields,
        default=None,
        metavar="FIELDS",
        help="--model rig: the rig's fields to estimate, separated by commas "
        "(e.g. flexural_rigidity,hub_inertia; input_delay, s, delays the "
        "record's input before the rig); the others are held at --rig's "
        "(no default: --model rig needs it)",
    )
    p.add_argument(
        "--sensor",
        default=None,
        metavar="SENSORS",
        help="--model rig: the rig's sensor the record's output holds "
        "(hub_angle, hub_velocity, end_acceleration, tip_deflection), or several "
        "separated by commas, one per --output column in its order (each "
        "weighted by its noise variance); default the record's output names",
    )
    p.add_argument(
        "--modes",
        type=_positive_int,
        default=None,
        help="--model rig: keep this many flexible modes (default all; fewer "
        "run faster)",
    )
    p.add_argument(
        "--rig",
        choices=["default", "nonlinear"],
        default="default",
        help="--model rig: the preset that starts the free fields and holds "
        "the others (nonlinear: hub friction and a torque limit on)",
    )


def _structure(args, data):
    """The rig grey box the options describe, for the record `data`."""
    from spiralid.fms import FlexibleManipulator, nonlinear_rig
    from spiralid.fms.greybox import RigGreyBox

    if args.free is None:
        raise UsageError("--model rig needs --free FIELDS (the fields to estimate)")
    rig = nonlinear_rig() if args.rig == "nonlinear" else FlexibleManipulator()
    if args.sensor is None:
        sensors = list(data.output_names)
    else:
        sensors = [part.strip() for part in str(args.sensor).split(",")]
    if len(sensors) != data.n_outputs:
        raise UsageError(
            f"--sensor names {len(sensors)} sensor(s) ({', '.join(sensors)}) but the "
            f"record holds {data.n_outputs} output(s) "
            f"({', '.join(data.output_names)}): one sensor per --output column"
        )
    sensor = sensors[0] if len(sensors) == 1 else tuple(sensors)
    try:
        return RigGreyBox(args.free, rig, output=sensor, n_modes=args.modes)
    except (TypeError, ValueError) as error:
        # The sensor defaults to the record's output name, which the
        # message would otherwise leave unexplained.
        hint = ""
        if args.sensor is None and "`output`" in str(error):
            hint = " (the record's output name; set --sensor)"
        elif "`output`" in str(error):
            hint = " (from --sensor)"
        raise UsageError(f"--model rig: {error}{hint}") from None


def run_rig(args, options: dict, write_model, validated, write_timings) -> int:
    """`spiralid identify --model rig`: load, fit, validate on both parts,
    write model.json, validation.json, summary.txt (with the fitted modes
    beside the finite-element model's) and the validation figures."""
    from spiralid.sysid import identify

    with _progress(args) as progress:
        progress.phase("load", "loading the data")
        data = _load_data(args)
        if args.detrend:
            data = _detrended(data, args.fraction)
        structure = _structure(args, data)
        est, val = data.split(args.fraction)
        with _open_folder(args.out, args.force) as folder:
            progress.phase("estimation", f"estimating {structure} by {args.method}")
            model = identify(est, structure, method=args.method, **options)
            progress.phase("validation", "validating on both parts")
            v_est, v_val = validated(model, est, val, args.method)
            progress.phase("writing", "writing files and figures")
            staged = folder.path
            headline = "\n".join(
                [
                    f"{structure} by {args.method} on {args.data}",
                    *model.parameter_rows(),
                    *(f"  {note}" for note in model.undetermined),
                    *model.output_rows(),
                    "",
                    structure.modes_beside(model.values),
                ]
            )
            summary = write_model(staged, model, v_est, v_val, headline)
            _save_figures(v_val.plot(), staged, "validation_")
            write_timings(staged, progress)
            written = folder.commit(last="model.json")
    if not args.quiet:
        print(summary)
        print(f"\nwrote {_listing(written, args.out)}")
    return 0
