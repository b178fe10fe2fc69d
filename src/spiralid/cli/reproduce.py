"""``spiralid reproduce``: the paper's SDA vs Eb-SDA experiment."""

from __future__ import annotations

import shlex
from pathlib import Path

from .errors import UsageError
from .options import (
    _add_data_options,
    _add_initial_option,
    _add_output_options,
    _add_points_option,
    _command,
    _load_data,
    _nonneg_int,
    _open_folder,
    _positive_int,
    _progress,
)


def run(args, argv: list[str]) -> int:
    from spiralid import datasets
    from spiralid.report import summary_text, write_reproduction
    from spiralid.reproduction import reproduce

    data = source = None
    if args.data is None and (
        args.input,
        args.output,
        args.ts,
        args.input_unit,
        args.output_unit,
    ) != ((None,) * 5):
        raise UsageError(
            "--input, --output, --ts and the units describe --data; give --data too"
        )
    if args.all_outputs and args.data is not None:
        raise UsageError(
            "--all-outputs identifies the simulated rig's modes from its four "
            "sensors; it does not apply to --data (a record of one output)"
        )
    with _progress(args) as progress:
        if args.data is not None:
            progress.phase("load", "loading the data")
            data = _load_data(args)
            source = (
                {"kind": "shipped data set", "name": args.data}
                if not Path(args.data).exists() and args.data in datasets.NAMES
                else {"kind": "user data", "path": str(Path(args.data).resolve())}
            )
        with _open_folder(args.out, args.force) as folder:
            progress.phase("runs", "running the experiment", unit="runs")
            rep = reproduce(
                data,
                seeds=range(args.first_seed, args.first_seed + args.seeds),
                max_nfev=args.budget,
                n_points=args.points,
                initial=args.initial,
                all_outputs=args.all_outputs,
                source=source,
                workers=args.workers,
                progress=progress,
            )
            progress.phase("writing", "writing the figures and the report")
            command = "spiralid " + shlex.join(argv)
            write_reproduction(rep, folder, command=command)
    if not args.quiet:
        print(summary_text(rep))
        print(f"\nwrote figures, results.json and report.html in {args.out}")
    return 0


_DESCRIPTION = (
    "Identify ARX(8, 8, 0) by SDA and Eb-SDA (paper-faithful and reflection "
    "parametrisations, refine, gain sensitivity) over several seeds at an "
    "equal budget, beside least squares and output error; write Table-2, "
    "Figures 6-7, results.json and report.html into --out."
)


def add_parser(sub) -> None:
    p = _command(
        sub,
        "reproduce",
        "the paper's SDA vs Eb-SDA experiment with baselines and statistics",
        _DESCRIPTION,
        run,
    )
    p.add_argument("--seeds", type=_positive_int, default=6, help="number of seeds")
    p.add_argument("--first-seed", type=_nonneg_int, default=0, help="first seed")
    p.add_argument(
        "--budget", type=_positive_int, default=20_000, help="cost evaluations per run"
    )
    _add_points_option(p)
    p.add_argument(
        "--workers",
        type=_positive_int,
        default=None,
        help="processes (default: one per core)",
    )
    p.add_argument(
        "--data",
        default=None,
        help="your own CSV/NPZ/MAT record, or 'robot_arm' (the shipped DaISy arm) "
        "(default: the simulated rig's paper experiment)",
    )
    _add_data_options(p, several_outputs=False, positional=False)
    _add_initial_option(p)
    p.add_argument(
        "--all-outputs",
        action="store_true",
        help="also identify the rig's modes from all four sensors of the same "
        "run (hub angle, hub velocity, end-point acceleration, tip deflection: "
        "one denominator, ARX(10, 10, 1), integrators 2,1,0,0) beside the "
        "paper's single-output model; the simulated rig only",
    )
    _add_output_options(p, "spiralid-reproduce")
