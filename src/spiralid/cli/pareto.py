"""``spiralid pareto``: a Pareto front of ARX models, the knee validated."""

from __future__ import annotations

import argparse
import csv
import json

from .errors import UsageError
from .identify import _validated, _write_timings, write_arx_model
from .options import (
    _add_by_fit_option,
    _add_data_options,
    _add_detrend_option,
    _add_fraction_option,
    _add_method_option,
    _add_order_options,
    _add_output_options,
    _add_parametrization_option,
    _add_points_option,
    _add_seed_option,
    _command,
    _detrended,
    _given,
    _interval,
    _listing,
    _load_data,
    _nonneg_float,
    _nonneg_int,
    _open_folder,
    _orders,
    _positive_int,
    _progress,
    _refuse_inapplicable,
)


def _objectives(text: str) -> tuple[str, ...]:
    return tuple(v.strip() for v in text.split(",") if v.strip())


_coherence = _interval(0.0, 1.0)


# Each objective as front.csv names its column (with its unit, as the
# records `spiralid simulate` writes name theirs) and as the summary says it.
_COLUMNS = {
    "cost": "cost_pct",
    "one-step": "one_step_pct",
    "frequency": "frequency_dB",
    "order": "parameters",
}
_SAID = {
    "cost": ("cost", "cost {:.4g} % of rms(y)"),
    "one-step": ("one-step cost", "one-step cost {:.4g} % of rms(y)"),
    "frequency": ("frequency error", "frequency error {:.4g} dB"),
    "order": ("parameters", "parameters (na + nb) {:.0f}"),
}


def _write_front(staged, front) -> None:
    """front.csv (one row per point) and point-<i>/model.json."""
    with open(staged / "front.csv", "w", newline="", encoding="utf-8") as fh:
        # "\n" as every file spiralid writes (the csv module's default is
        # "\r\n").
        out = csv.writer(fh, lineterminator="\n")
        columns = [_COLUMNS[n] for n in front.names]
        out.writerow(["point", "na", "nb", "nk", "start", *columns, "knee"])
        for i, (model, row) in enumerate(
            zip(front.models, front.objectives, strict=True)
        ):
            arx = model.arx
            values = [f"{v:.10g}" for v in row]
            knee = int(i == front.knee)
            out.writerow([i, arx.na, arx.nb, arx.nk, model.result.start, *values, knee])
    for i, model in enumerate(front.models):
        folder = staged / f"point-{i}"
        folder.mkdir()
        (folder / "model.json").write_text(
            json.dumps(model.to_dict(timings=False), indent=2)
        )


def run(args, argv: list[str]) -> int:
    from spiralid.report.pareto_figures import front_figure

    # Every option is checked before the search, which may take minutes.
    _refuse_conflicts(args)
    with _progress(args) as progress:
        progress.phase("load", "loading the data")
        data = _load_data(args)
        if args.detrend:
            data = _detrended(data, args.fraction)
        structure, structures = _structures(args)
        est, val = data.split(args.fraction)
        for arx in structures:
            arx.check_length(est, "estimation part of DATA")
        with _open_folder(args.out, args.force) as folder:
            what = ", ".join(map(str, structures))
            progress.phase(
                "search", f"searching the front of {what}", unit="evaluations"
            )
            front = _search(args, est, structure, progress)
            progress.phase("validation", "choosing a point and validating it")
            chosen, why = _choose(args, front, est, val)
            model = front.models[chosen]
            v_est, v_val = _validated(model, est, val, f"point {chosen}")
            progress.phase("writing", "writing the front, files and figures")
            staged = folder.path
            _write_front(staged, front)
            model.fraction = args.fraction
            front_figure(front, chosen).savefig(staged / "front.png", dpi=110)
            headline = _headline(args, front, chosen, why)
            summary = write_arx_model(staged, model, v_est, v_val, headline)
            _write_timings(staged, progress)
            # With --force, an earlier and larger front's surplus points go.
            written = folder.commit(last="model.json", sets="point-[0-9]*")
    if not args.quiet:
        print(summary)
        files = [p for p in written if not p.name.startswith("point-")]
        points = (
            f"point-0..{len(front) - 1}/model.json"
            if len(front) > 1
            else "point-0/model.json"
        )
        print(f"\nwrote {points}, {_listing(files, args.out)}")
    return 0


def _refuse_conflicts(args) -> None:
    """Options that contradict each other, or that the objectives leave
    unused, end the command before anything is loaded."""
    if args.orders is not None and _given(args, "--na", "--nb"):
        raise UsageError("--orders replaces --na and --nb (each order n is ARX(n, n))")
    if args.max_frequency is not None and args.by_fit is not None:
        raise UsageError("give --max-frequency or --by-fit, not both")
    if args.by_fit is not None and (args.orders is None or len(args.orders) < 2):
        raise UsageError("--by-fit chooses among orders: give --orders")
    if "frequency" not in args.objectives and args.max_frequency is not None:
        raise UsageError("--max-frequency needs the frequency objective")
    _check_options(args)


# The flags that set identify_pareto's options, and the option each sets.
_OPTION_FLAGS = {
    "--points": "n_points",
    "--budget": "max_nfev",
    "--parametrization": "parametrization",
    "--no-seeds": "seed_estimates",
    "--polish": "extremes_nfev",
    "--min-coherence": "min_coherence",
}


def _option_values(args) -> dict:
    """identify_pareto's options as the command's flags set them, by name."""
    values = {
        name: getattr(args, flag[2:].replace("-", "_"))
        for flag, name in _OPTION_FLAGS.items()
    }
    values["seed_estimates"] = not args.no_seeds
    return values


def _passed(args) -> dict:
    """What `run` passes to identify_pareto: the options that apply to the
    objectives (pareto_options), as the flags set them."""
    from spiralid.sysid.estimation.pareto.options import pareto_options

    takes = pareto_options(args.objectives)
    return {name: v for name, v in _option_values(args).items() if name in takes}


def _check_options(args) -> None:
    """Refuse every typed flag whose option identify_pareto would refuse
    from Python for these objectives (refused_pareto_options, from the same
    table, pareto_options), naming the flags that do apply."""
    from spiralid.sysid.estimation.pareto.options import (
        pareto_options,
        refused_pareto_options,
    )

    values = _option_values(args)
    typed = {
        _OPTION_FLAGS[f]: values[_OPTION_FLAGS[f]] for f in _given(args, *_OPTION_FLAGS)
    }
    refused = refused_pareto_options(args.objectives, typed)
    if refused:
        flags = [f for f, name in _OPTION_FLAGS.items() if name in refused]
        takes = pareto_options(args.objectives)
        where = f"--objectives {','.join(args.objectives)}"
        _refuse_inapplicable(flags, _OPTION_FLAGS, takes, where)


def _structures(args) -> tuple:
    """What identify_pareto is given (one ARX, or the orders) and the ARX
    structures it searches."""
    from spiralid.sysid import ARX

    if args.orders is None:
        structure = ARX(args.na, args.nb, args.nk)
        return structure, [structure]
    return args.orders, [ARX(n, n, args.nk) for n in args.orders]


def _search(args, est, structure, progress):
    """The front, by identify_pareto with the command's options."""
    from spiralid.sysid import identify_pareto

    return identify_pareto(
        est,
        structure,
        args.objectives,
        method=args.method,
        rng=args.seed,
        nk=args.nk,
        progress=progress,
        **_passed(args),
    )


def _choose(args, front, est, val) -> tuple[int, str]:
    """The point to validate and write, and why it was chosen."""
    from spiralid.sysid import choose, choose_order

    if args.max_frequency is not None:
        chosen = choose(front, max_frequency=args.max_frequency)
        return chosen, f"lowest cost with frequency error <= {args.max_frequency:g} dB"
    if args.by_fit is not None:
        chosen = choose_order(front, val, warmup=est, tolerance=args.by_fit)
        return chosen, (
            f"lowest order within {args.by_fit:g} points of the best "
            "validation fit, chosen on the validation part (its fit is "
            "optimistic)"
        )
    return front.knee, "the knee"


def _headline(args, front, chosen: int, why: str) -> str:
    """The summary's first line: the front, and the chosen point's model and
    objectives with their units."""
    model = front.models[chosen]
    values = ", ".join(
        _SAID[n][1].format(v)
        for n, v in zip(front.names, front.objectives[chosen], strict=True)
    )
    objectives = ", ".join(_SAID[n][0] for n in front.names)
    return (
        f"Pareto front of {len(front)} stable models ({objectives}) by "
        f"{args.method} on {args.data}, {front.nfev} evaluations; point "
        f"{chosen} ({why}): {model.arx}, {values}, H(z) = "
        f"{model.tf_string()}"
    )


_DESCRIPTION = (
    "Search a Pareto front of stable ARX models on the first --fraction of "
    "DATA by the multi-objective spiral search; write front.csv, front.png "
    "and point-<i>/model.json, and validate the knee (or the --max-frequency "
    "choice) as `spiralid identify` does."
)


def add_parser(sub) -> None:
    p = _command(
        sub,
        "pareto",
        "a Pareto front of ARX models (time and frequency errors)",
        _DESCRIPTION,
        run,
    )
    _add_data_options(p, several_outputs=False)
    _add_order_options(p)
    _add_front_options(p)
    _add_detrend_option(p)
    _add_points_option(p)
    p.add_argument(
        "--budget",
        type=_positive_int,
        default=5000,
        help="cost evaluations of each order's search",
    )
    p.add_argument(
        "--polish",
        type=_nonneg_int,
        default=200,
        help="evaluations of each extreme's local polish (0: none)",
    )
    p.add_argument(
        "--no-seeds",
        action="store_true",
        help="do not seed the search with the LS, Steiglitz-McBride and OE estimates",
    )
    p.add_argument(
        "--min-coherence",
        type=_coherence,
        default=0.5,
        help="frequency bins with lower input-output coherence are not scored",
    )
    _add_choice_options(p)
    _add_seed_option(p)
    _add_fraction_option(p)
    _add_output_options(p, "spiralid-pareto")


def _add_front_options(p: argparse.ArgumentParser) -> None:
    """What the front spans (--orders, --objectives) and the search that
    finds it (--method, --parametrization)."""
    # Names only: building the parser loads no estimator.
    from spiralid.choices import (
        DEFAULT_PARETO_METHOD,
        OBJECTIVES,
        PARETO_METHOD_NAMES,
    )

    p.add_argument(
        "--orders",
        type=_orders,
        default=None,
        help="several orders n, each ARX(n, n, nk), e.g. 2:12 or 2,4,8; adds the "
        "number of parameters as an objective (default: none, the one ARX(--na, "
        "--nb, --nk))",
    )
    p.add_argument(
        "--objectives",
        type=_objectives,
        default=("cost", "frequency"),
        help=f"comma-separated, among {', '.join(OBJECTIVES)} "
        "(default: cost,frequency)",
    )
    _add_method_option(
        p,
        PARETO_METHOD_NAMES,
        DEFAULT_PARETO_METHOD,
        "spiral rule of the search (ebsda: the paper's Eb-SDA)",
    )
    _add_parametrization_option(
        p,
        "modal",
        "what the search moves (modal: the denominator's modes, numerator "
        "projected out)",
    )


def _add_choice_options(p: argparse.ArgumentParser) -> None:
    """Which point of the front is validated, instead of the knee."""
    p.add_argument(
        "--max-frequency",
        type=_nonneg_float,
        default=None,
        help="validate the lowest-cost point with a frequency error at most this "
        "many dB instead of the knee (default: none, the knee)",
    )
    _add_by_fit_option(
        p,
        "validate the lowest order whose lowest-cost model's validation fit "
        "is within POINTS of the best order's, instead of the knee (with "
        "--orders; default: none, the knee)",
    )
