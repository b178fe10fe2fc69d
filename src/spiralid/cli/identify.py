"""``spiralid identify``: estimate a model on a record and validate it."""

from __future__ import annotations

import argparse
import json
import shlex

from .errors import UsageError
from .options import (
    _add_by_fit_option,
    _add_data_options,
    _add_detrend_option,
    _add_fraction_option,
    _add_initial_option,
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
    _open_folder,
    _orders,
    _positive_int,
    _progress,
    _refuse_inapplicable,
    _refuse_unused,
    _save_figures,
)
from .rig import RIG_FLAGS, add_rig_options, run_rig


def _structure(args):
    from spiralid.sysid import ARX

    return ARX(args.na, args.nb, args.nk)


_holdout = _interval(0.0, 0.5)


def _time_constant(text: str) -> float | str | None:
    """--max-time-constant: seconds > 0, 'none' (no margin) or 'auto' (the
    estimation part's length for the methods it applies to)."""
    word = text.strip().lower()
    if word in ("none", "auto"):
        return None if word == "none" else "auto"
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not (v > 0 and v < float("inf")):
        import argparse

        raise argparse.ArgumentTypeError(
            f"must be a number of seconds > 0 or 'none'; got {text!r}"
        )
    return v


def _folds(text: str) -> bool | str:
    """--folds: on, off or auto (identify's True, False or "auto")."""
    words = {"on": True, "off": False, "auto": "auto"}
    word = text.strip().lower()
    if word not in words:
        raise argparse.ArgumentTypeError(f"must be on, off or auto; got {text!r}")
    return words[word]


def _integrator_count(text: str) -> int | tuple[int, ...]:
    """--integrator K: a count of known integrators, 0 or more; or one per
    output separated by commas (2,1,0,0) with several --output columns."""
    counts = []
    for part in text.split(","):
        try:
            counts.append(int(part))
        except ValueError:
            counts.append(-1)
    if min(counts) < 0:
        import argparse

        raise argparse.ArgumentTypeError(
            f"must be a count of integrators >= 0, or one per output (2,1,0); "
            f"got {text!r}"
        )
    return counts[0] if len(counts) == 1 else tuple(counts)


def _narx_structure(args):
    """--model narx / polynomial: --na past outputs, --nb past inputs
    (the largest of --by-fit's candidates, which the record must fit)."""
    return _narx_structures(args)[-1]


def _narx_structures(args) -> list:
    """The structures --by-fit chooses among: every --lags n (past outputs
    and inputs both n; default --na and --nb) with every --hidden size, by
    increasing size; one structure without --by-fit."""
    lags = [(n, n) for n in args.lags] if args.lags else [(args.na, args.nb)]
    hidden = args.hidden if args.model == "narx" else [None]
    grid = [_one_narx(args, na, nb, h) for na, nb in lags for h in hidden]
    return sorted(grid, key=lambda st: st.n_params)


def _one_narx(args, na: int, nb: int, hidden: int | None):
    from spiralid.sysid import NARX, PolynomialNARX

    if na < 1:
        raise UsageError(f"--model {args.model} needs --na >= 1; got {na}")
    # A NARX's linear start takes up to two known integrators (a hub angle
    # driven by a torque has two); forward regression has one at most.
    most = 2 if args.model == "narx" else 1
    if isinstance(args.integrator, tuple):
        raise UsageError(
            f"--integrator {','.join(map(str, args.integrator))}: one count per "
            "output applies to several --output columns, not to --model "
            f"{args.model}"
        )
    if args.integrator > most:
        raise UsageError(
            f"--model {args.model} takes at most {most} integrator(s); got "
            f"--integrator {args.integrator}"
        )
    if args.model == "narx":
        return NARX(
            na,
            nb,
            args.nk,
            hidden=(hidden,),
            activation=args.activation,
            integrator=int(args.integrator),
        )
    return PolynomialNARX(
        na,
        nb,
        args.nk,
        degree=args.degree,
        n_terms=args.terms,
        integrator=bool(args.integrator),
    )


def _nss_structure(args):
    """--model nss: a neural state space of --order states and --hidden
    units in each network."""
    from spiralid.sysid import NeuralStateSpace

    if len(args.hidden) > 1:
        raise UsageError("--model nss takes one --hidden size")
    return NeuralStateSpace(args.order, hidden=(args.hidden[0],))


def _load_parts(args, progress, make_structure):
    """DATA loaded (detrended when asked), the structure built from the
    options, and the record split: the structure must fit the estimation
    part."""
    progress.phase("load", "loading the data")
    data = _load_data(args)
    if args.detrend:
        data = _detrended(data, args.fraction)
    structure = make_structure(args)
    est, val = data.split(args.fraction)
    structure.check_length(est, "estimation part of DATA")
    return structure, est, val


def _run_narx(args) -> int:
    """`spiralid identify --model narx|polynomial`."""
    from spiralid.sysid import identify

    with _progress(args) as progress:
        make = _nss_structure if args.model == "nss" else _narx_structure
        structure, est, val = _load_parts(args, progress, make)
        options = _identify_options(args, structure)
        with _open_folder(args.out, args.force) as folder:
            steps = _search_steps(args, narx=True)
            what = f"estimating {structure} by {args.method}"
            progress.phase("estimation", what, **steps)
            if steps:
                options["callback"] = _search_callback(progress, steps, args)
            if args.by_fit is None:
                model, chosen = (
                    identify(est, structure, method=args.method, **options),
                    "",
                )
            else:
                model, chosen = _chosen_by_fit(args, est, val, options, progress)
            model.fraction = args.fraction
            progress.phase("validation", "validating on both parts")
            v_est, v_val = _validated(model, est, val, args.method)
            progress.phase("writing", "writing files and figures")
            staged = folder.path
            headline = f"{model.structure} by {args.method} on {args.data}{chosen}"
            summary = _write_model(staged, model, v_est, v_val, headline)
            _save_figures(v_val.plot(), staged, "validation_")
            _write_timings(staged, progress, model)
            written = folder.commit(last="model.json")
    if not args.quiet:
        print(summary)
        print(f"\nwrote {_listing(written, args.out)}")
    return 0


def _chosen_by_fit(args, est, val, options, progress):
    """--by-fit POINTS: every candidate structure fitted on the estimation
    part and validated, and the smallest (by number of parameters) whose
    validation fit is within POINTS of the best, the best-fitting of several
    of that size (choose_order's rule); the model and the lines that say how
    it was chosen, one per candidate."""
    from spiralid.sysid import identify, validation_fits
    from spiralid.sysid.validation.selection import lowest_within

    structures = _narx_structures(args)
    models = []
    for k, st in enumerate(structures, 1):
        progress.phase("estimation", f"candidate {k}/{len(structures)}: {st}")
        models.append(identify(est, st, method=args.method, **options))
    # Each candidate validated once: the table below and the choice read
    # the same fits.
    fits = validation_fits(models, val, warmup=est)
    best = models[lowest_within(fits, args.by_fit)]
    lines = [
        f"\nchosen by validation fit (--by-fit {args.by_fit:g}): the smallest "
        f"candidate within {args.by_fit:g} points of the best (of equal sizes, "
        "the better fit); its validation fit below is optimistic, as it was "
        "chosen on that part"
    ]
    lines += [
        f"  {models[i].structure}: {n} parameters, validation fit {fit:.2f} %"
        + ("  <- chosen" if models[i] is best else "")
        for n, i, fit in fits
    ]
    return best, "\n".join(lines)


# The budget of the searches that have one of their own (identify's
# "spiral", spiral/recommended.py's _estimate_recommended, and every NARX search,
# narx.estimate_search and estimate_spiral), and the iteration cap of the
# others (spiralid.optim.minimize, differential_evolution): what --help says
# and what the progress counts toward.
_DEFAULT_BUDGET = 10_000
_DEFAULT_ITERATIONS = 500


def _search_steps(args, narx: bool = False) -> dict:
    """What the search's progress counts toward: ``{"total", "unit"}``, or
    nothing for a method that does not search (or does not report: the
    NARX "spiral")."""
    from spiralid.sysid import METHODS

    if not METHODS[args.method].search or (narx and args.method == "spiral"):
        return {}
    if args.budget is not None or args.method == "spiral" or narx:
        return {"total": args.budget or _DEFAULT_BUDGET, "unit": "evaluations"}
    return {"total": args.iterations or _DEFAULT_ITERATIONS, "unit": "iterations"}


def _search_callback(progress, steps: dict, args):
    """The search's ``callback(intermediate_result)``: reports its
    evaluations (or iterations) to `progress`; never asks it to stop."""
    if steps["unit"] == "iterations":
        return lambda res: progress(int(res.nit))
    if args.method == "de":
        # SciPy counts calls, one population per generation.
        return lambda res: progress(args.points * (int(res.nit) + 1))
    return lambda res: progress(int(res.nfev))


def _validated(model, est, val, label: str):
    """The validations of `model` on the estimation and validation parts."""
    from spiralid.sysid import validate

    v_est = validate(model, est, label=f"{label} (estimation)")
    v_val = validate(model, val, warmup=est, label=f"{label} (validation)")
    return v_est, v_val


def _write_model(staged, model, v_est, v_val, headline: str) -> str:
    """model.json, validation.json and summary.txt of a fitted model (ARX
    or NARX); returns the summary. model.json holds what the seed decides,
    byte for byte the same on a rerun; the wall times go beside it
    (:func:`_write_timings`)."""
    (staged / "model.json").write_text(
        json.dumps(model.to_dict(timings=False), indent=2)
    )
    (staged / "validation.json").write_text(
        json.dumps(
            {"estimation": v_est.to_dict(), "validation": v_val.to_dict()}, indent=2
        )
    )
    summary = "\n\n".join(
        [
            headline,
            f"{getattr(model, 'cost_label', 'estimation cost (eq. 2)')}: "
            f"{model.cost:.6g}",
            v_est.summary(),
            v_val.summary(),
        ]
    )
    (staged / "summary.txt").write_text(summary + "\n")
    return summary


def write_arx_model(staged, model, v_est, v_val, headline: str) -> str:
    """An ARX model and its validations on both parts of the record, written
    as ``spiralid identify`` writes them (:func:`_write_model` and the
    estimation and validation figures); returns the summary."""
    summary = _write_model(staged, model, v_est, v_val, headline)
    _save_figures(v_val.plot(), staged, "validation_")
    _save_figures(v_est.plot(), staged, "estimation_")
    return summary


def _run_shared(args, progress, arx, est, val, options, argv) -> int:
    """`spiralid identify --output a,b,...`: one denominator for every
    output (identify on a record of several outputs), validated output by
    output with a joint fit; report.html holds the modes, the fits, each
    output's figures and a stabilisation diagram."""
    from spiralid.report.shared_output import write_shared_report
    from spiralid.sysid import identify, stabilisation, validate

    with _open_folder(args.out, args.force) as folder:
        progress.phase(
            "estimation",
            f"estimating {arx} for {est.n_outputs} output(s) of {est.n_inputs} "
            "input(s)",
        )
        model = identify(est, arx, method=args.method, **options)
        model.fraction = args.fraction
        progress.phase("validation", "validating every output on both parts")
        v_est = validate(model, est, label=f"{args.method} (estimation)")
        v_val = validate(model, val, warmup=est, label=f"{args.method} (validation)")
        orders = _stabilisation_orders(arx, est)
        progress.phase("stabilisation", f"output error at orders {orders}")
        same = {k: v for k, v in options.items() if k in _STABILISATION_OPTIONS}
        diagram = stabilisation(
            est, orders, nk=arx.nk, method=_STABILISATION_METHOD, **same
        )
        progress.phase("writing", "writing files and figures")
        staged = folder.path
        # The wall times go to timings.json, so that model.json is what the
        # seed decides, byte for byte the same on a rerun.
        (staged / "model.json").write_text(
            json.dumps(model.to_dict(timings=False), indent=2)
        )
        (staged / "validation.json").write_text(
            json.dumps(
                {"estimation": v_est.to_dict(), "validation": v_val.to_dict()}, indent=2
            )
        )
        headline = (
            f"{arx} with one denominator for {', '.join(model.output_names)} "
            f"on {args.data}"
        )
        summary = "\n\n".join(
            [
                headline,
                f"joint cost (weighted, % RMS): {model.cost:.6g}",
                v_est.summary(modes=False),
                v_val.summary(),
            ]
        )
        (staged / "summary.txt").write_text(summary + "\n")
        write_shared_report(
            staged,
            model,
            v_est,
            v_val,
            headline=headline,
            diagram=diagram,
            data=est,
            stabilisation_note=_stabilisation_note(orders),
            command="spiralid " + shlex.join(argv),
        )
        _write_timings(staged, progress, model)
        written = folder.commit(last="model.json")
    if not args.quiet:
        print(summary)
        print(f"\nwrote {_listing(written, args.out)}")
    return 0


# The stabilisation diagram of several outputs: output error (the
# Gauss-Newton polish from the least-squares and subspace denominators, no
# search) at every other order from 6 below the model's to 2 above, about
# as long as the spiral search at the model's order alone on the rig.
_STABILISATION_METHOD = "oe"
_STABILISATION_OPTIONS = ("integrator", "max_time_constant")


def _stabilisation_orders(arx, est) -> list[int]:
    """``na - 6, na - 4, ..., na + 2`` (at least 1; ``[2]`` for na = 0),
    without the orders whose structure the estimation part is too short
    for."""
    from spiralid.sysid import ARX

    orders = [n for n in range(arx.na - 6, arx.na + 3, 2) if n >= 1] or [2]
    fit = []
    for n in orders:
        try:
            ARX(n, n, arx.nk).check_length(est, "estimation part")
        except ValueError:
            continue
        fit.append(n)
    return fit or [arx.na]


def _stabilisation_note(orders: list[int]) -> str:
    return (
        f"Each order na = {', '.join(map(str, orders))} identified as "
        f"ARX(na, na, nk) by output error (method "
        f"'{_STABILISATION_METHOD}', the same known integrators), whatever "
        "--method fitted the model: a fast fit at each order rather than a "
        "search."
    )


def _write_timings(staged, progress, model=None) -> None:
    """timings.json: the seconds of each phase of the command (load,
    estimation or search, validation, writing), the estimator's own parts
    after its phase (the search and the polish of ``model.timings``) and
    the command's total; written last, just before the commit."""
    phases = progress.timings()
    total = phases.pop("total")
    own = {} if model is None else model.timings
    own = {k: float(v) for k, v in own.items() if k != "total" and k not in phases}
    times = {}
    for name, seconds in phases.items():
        times[name] = seconds
        if name == "estimation":
            times.update(own)
    times.update({k: v for k, v in own.items() if k not in times})
    times["total"] = total
    (staged / "timings.json").write_text(json.dumps(times, indent=2))


# The command's flags for identify()'s options: a typed flag is refused
# exactly when identify() refuses its value for the method and structure
# (--integrator is the structure's own for a NARX).
_OPTION_FLAGS = {
    "--predictor": "predictor",
    "--initial": "initial",
    "--seed": "rng",
    "--integrator": "integrator",
    "--max-time-constant": "max_time_constant",
    "--parametrization": "parametrization",
    "--refine": "refine",
    "--points": "n_points",
    "--iterations": "max_iter",
    "--budget": "max_nfev",
    "--holdout": "holdout",
    "--noise": "noise",
    "--folds": "folds",
    "--training": "training",
    "--horizon": "horizon",
    "--workers": "workers",
}
# Flags whose None stands for "not typed": identify() then applies its own
# default (one place decides it, and a changed default reaches the CLI).
_LIBRARY_DEFAULTS = (
    "max_iter",
    "max_nfev",
    "parametrization",
    "noise",
    "folds",
    "training",
    "horizon",
    "workers",
)
_DESTS = {flag: flag.removeprefix("--").replace("-", "_") for flag in _OPTION_FLAGS}

# The structure options of one kind of --model: the models they apply to.
_MODEL_FLAGS = {
    "--hidden": ("narx", "nss"),
    "--order": ("nss",),
    "--lags": ("narx", "polynomial"),
    "--by-fit": ("narx", "polynomial"),
    "--activation": ("narx",),
    "--degree": ("polynomial",),
    "--terms": ("polynomial",),
    **dict.fromkeys(RIG_FLAGS, ("rig",)),
}


def _example_structure(model: str):
    """A structure of the kind --model asks for (its options' table)."""
    from spiralid.sysid import ARX, NARX, PolynomialNARX

    if model == "rig":
        from spiralid.fms.greybox import RigGreyBox

        return RigGreyBox(["hub_inertia"])
    if model == "nss":
        from spiralid.sysid import NeuralStateSpace

        return NeuralStateSpace(1)
    kinds = {"arx": ARX, "narx": NARX, "polynomial": PolynomialNARX}
    return kinds[model](1, 1, 0)


def _option_values(args) -> dict:
    """identify()'s options as the command's flags set them, by name."""
    values = {name: getattr(args, _DESTS[flag]) for flag, name in _OPTION_FLAGS.items()}
    if args.model != "arx":
        del values["integrator"]
    return values


def _identify_options(args, structure) -> dict:
    """What `run` passes to identify(): the options that apply to the
    method and structure (identify_options), less the budgets not given."""
    from spiralid.sysid.estimation.core.identify import identify_options

    takes = identify_options(args.method, structure, args.refine)
    return {
        name: value
        for name, value in _option_values(args).items()
        if name in takes and not (value is None and name in _LIBRARY_DEFAULTS)
    }


def _check_candidates(args) -> None:
    """--by-fit, --lags and several --hidden sizes belong together, and to
    the NARX models."""
    several = [
        f
        for f, v in (("--hidden", args.hidden), ("--lags", args.lags))
        if v and len(v) > 1
    ]
    if args.by_fit is None and several:
        raise UsageError(
            f"several values of {' and '.join(several)} need --by-fit POINTS to "
            "choose among them"
        )
    if args.model == "arx" and (args.by_fit is not None or args.lags):
        raise UsageError(
            "--by-fit and --lags choose among NARX structures (--model narx or "
            "polynomial); ARX orders are chosen by `spiralid pareto --orders "
            "--by-fit`"
        )
    if args.lags and _given(args, "--na", "--nb"):
        raise UsageError("--lags replaces --na and --nb (each lag count n is n, n)")


def _check_shared_options(args, est) -> None:
    """The method and typed flags a fit of several outputs takes (the
    library's table, shared_options), refused by their flags."""
    from spiralid.sysid.estimation.shared.denominator import (
        SHARED_METHODS,
        shared_options,
    )

    outputs = (
        f"{est.n_outputs} outputs (one shared denominator)"
        if est.n_inputs == 1
        else f"{est.n_outputs} output(s) and {est.n_inputs} inputs (one shared "
        "denominator)"
    )
    if args.method not in SHARED_METHODS:
        raise UsageError(
            f"--method {args.method} takes one output; a record of {outputs} is "
            f"identified by --method {' or '.join(SHARED_METHODS)}"
        )
    takes = shared_options(args.method)
    refused = [f for f in _given(args, *_OPTION_FLAGS) if _OPTION_FLAGS[f] not in takes]
    _refuse_inapplicable(
        refused, _OPTION_FLAGS, takes, f"--method {args.method} on {outputs}"
    )


# The models --na, --nb and --nk do not size: their estimator family, and
# what sizes them instead.
_ORDERLESS = {"rig": ("greybox", ""), "nss": ("neural-state-space", " (--order)")}


def _check_options(args) -> None:
    """Refuse, before any data is read, what the model and method cannot
    do, and every typed option identify() would refuse from Python for this
    method and structure (identify_options, the one table), with the
    options that do apply."""
    from spiralid.sysid.estimation.core.families import ESTIMATORS, methods_of
    from spiralid.sysid.estimation.core.identify import (
        identify_options,
        refused_options,
    )

    model, method = args.model, args.method
    _check_candidates(args)
    if model in _ORDERLESS:
        family, instead = _ORDERLESS[model]
        if (family, method) not in ESTIMATORS:
            able = ", ".join(methods_of(family))
            raise UsageError(f"--method {method} does not fit --model {model}: {able}")
        _refuse_unused(
            _given(args, "--na", "--nb", "--nk"),
            f"to --model arx, narx and polynomial, not to --model {model}{instead}",
        )
    elif model != "arx" and ("narx", method) not in ESTIMATORS:
        able = ", ".join(methods_of("narx"))
        raise UsageError(f"--method {method} does not train NARX models: {able}")
    if model == "polynomial" and method != "ls":
        raise UsageError("--model polynomial is estimated by --method ls (FROLS)")
    for owners in dict.fromkeys(_MODEL_FLAGS.values()):
        flags = [f for f, o in _MODEL_FLAGS.items() if o == owners and model not in o]
        _refuse_unused(
            _given(args, *flags),
            f"to --model {' and '.join(owners)}, not to --model {model}",
        )
    structure = _example_structure(model)
    values = _option_values(args)
    typed = {
        _OPTION_FLAGS[f]: values[_OPTION_FLAGS[f]]
        for f in _given(args, *_OPTION_FLAGS)
        if _OPTION_FLAGS[f] in values
    }
    refused = refused_options(method, typed, structure)
    if refused:
        flags = [f for f, name in _OPTION_FLAGS.items() if name in refused]
        takes = identify_options(method, structure, args.refine)
        kind = "" if model == "arx" else f" --model {model}"
        _refuse_inapplicable(flags, _OPTION_FLAGS, takes, f"--method {method}{kind}")


def run(args, argv: list[str]) -> int:
    from spiralid.sysid import identify
    from spiralid.sysid.validation.plots import plot_convergence

    _check_options(args)
    if args.model == "rig":
        options = _identify_options(args, _example_structure("rig"))
        return run_rig(args, options, _write_model, _validated, _write_timings)
    if args.model != "arx":
        return _run_narx(args)
    with _progress(args) as progress:
        arx, est, val = _load_parts(args, progress, _structure)
        # The budget rule is identify()'s (spiral/population.py: search_options).
        options = _identify_options(args, arx)
        if est.n_outputs > 1 or est.n_inputs > 1:
            _check_shared_options(args, est)
            return _run_shared(args, progress, arx, est, val, options, argv)
        with _open_folder(args.out, args.force) as folder:
            steps = _search_steps(args)
            progress.phase("estimation", f"estimating {arx} by {args.method}", **steps)
            if steps:
                options["callback"] = _search_callback(progress, steps, args)
            model = identify(est, arx, method=args.method, **options)
            model.fraction = args.fraction
            progress.phase("validation", "validating on both parts")
            v_est, v_val = _validated(model, est, val, args.method)
            progress.phase("writing", "writing files and figures")
            staged = folder.path
            headline = (
                f"{arx} by {args.method} on {args.data}: H(z) = {model.tf_string()}"
            )
            summary = write_arx_model(staged, model, v_est, v_val, headline)
            if model.history is not None:
                plot_convergence(
                    {args.method: model.history},
                    cost_label="best cost, eq. (2) (% of rms(y))",
                ).savefig(staged / "convergence.png", dpi=110)
            _write_timings(staged, progress, model)
            written = folder.commit(last="model.json")
    if not args.quiet:
        print(summary)
        print(f"\nwrote {_listing(written, args.out)}")
    return 0


_DESCRIPTION = (
    "Estimate an ARX model on the first --fraction of DATA and validate it "
    "on the rest; write model.json, validation.json, summary.txt and figures "
    "into --out."
)


def add_parser(sub) -> None:
    p = _command(
        sub, "identify", "identify an ARX model from a data file", _DESCRIPTION, run
    )
    _add_data_options(p)
    _add_model_options(p)
    _add_order_options(p)
    _add_method_options(p)
    _add_search_options(p)
    _add_fraction_option(p)
    _add_output_options(p, "spiralid-identify")


def _add_model_options(p: argparse.ArgumentParser) -> None:
    """--model, and the options of the NARX families."""
    p.add_argument(
        "--model",
        choices=["arx", "narx", "polynomial", "nss", "rig"],
        default="arx",
        help="ARX, NARX with a one-hidden-layer perceptron (--na past outputs, "
        "--nb past inputs), polynomial NARX by forward-regression OLS, a neural "
        "state space (--order states, --hidden units; --method names its linear "
        "start's), or the flexible manipulator's physical parameters (--free)",
    )
    p.add_argument(
        "--order",
        type=_positive_int,
        default=3,
        help="--model nss: state dimension",
    )
    add_rig_options(p)
    p.add_argument(
        "--hidden",
        type=_orders,
        default=[10],
        help="NARX hidden units; several (4,8,16 or 4:8) for --by-fit to choose "
        "among; --model nss: each network's units",
    )
    p.add_argument(
        "--lags",
        type=_orders,
        default=None,
        help="NARX: several lag counts n (e.g. 2,4,8), each --na n --nb n, for "
        "--by-fit to choose among (default: --na and --nb)",
    )
    _add_by_fit_option(
        p,
        "--model narx or polynomial: fit and validate every --lags and "
        "--hidden candidate, list each, and keep the smallest (fewest parameters; "
        "of equal sizes, the better fit) whose validation fit is within POINTS of "
        "the best (default: none, one structure)",
    )
    p.add_argument(
        "--activation",
        choices=["tanh", "logistic", "linear"],
        default="tanh",
        help="NARX hidden units' activation",
    )
    p.add_argument(
        "--holdout",
        type=_holdout,
        default=0.2,
        help="NARX: share of the estimation part held back for early stopping "
        "(0: train to convergence)",
    )
    p.add_argument(
        "--training",
        choices=["free-run", "subsequences"],
        default=None,
        help="NARX: train on the free run of the whole record or on short "
        "stretches each started from measured samples (default: free-run)",
    )
    p.add_argument(
        "--horizon",
        type=_positive_int,
        default=None,
        metavar="SAMPLES",
        help="NARX --training subsequences, and --model nss: the stretches' "
        "length (default: a growing curriculum, kept by the held-back fit)",
    )
    p.add_argument(
        "--degree", type=_positive_int, default=2, help="polynomial NARX degree"
    )
    p.add_argument(
        "--terms", type=_positive_int, default=10, help="polynomial NARX terms"
    )


def _add_method_options(p: argparse.ArgumentParser) -> None:
    """--method and what shapes its cost: predictor, parametrisation, initial
    condition, detrending, polish, stability margin, integrators."""
    # Names only: building the parser loads no estimator (`spiralid --help`
    # stays quick).
    from spiralid.choices import DEFAULT_METHOD, METHOD_NAMES

    _add_method_option(
        p,
        METHOD_NAMES,
        DEFAULT_METHOD,
        "estimator: a search over the paper's cost, least squares or output error",
    )
    p.add_argument(
        "--predictor",
        choices=["simulation", "one-step"],
        default="simulation",
        help="error of the cost: free-run simulation or one-step prediction",
    )
    _add_parametrization_option(
        p,
        None,
        "what a search moves: the ARX coefficients (the paper), the "
        "denominator's reflection coefficients or modal frequencies and dampings "
        "(every candidate stable); default the method's own (modal for spiral)",
    )
    _add_initial_option(p)
    _add_detrend_option(p)
    p.add_argument(
        "--refine", action="store_true", help="polish a spiral result locally"
    )
    p.add_argument(
        "--max-time-constant",
        type=_time_constant,
        default="auto",
        metavar="SECONDS",
        help="stability margin: every pole's time constant at most this "
        "(|z| <= exp(-ts / T)); 'none' for no margin; default the estimation "
        "part's length, for --method spiral and oe and --refine's polish",
    )
    p.add_argument(
        "--noise",
        choices=["white", "integrated"],
        default=None,
        help="--method spiral and oe: the output's disturbance, white or "
        "integrated (a drifting output: the fit runs on the differenced record, "
        "as MATLAB's IntegrateNoise; default: white)",
    )
    p.add_argument(
        "--folds",
        type=_folds,
        default=None,
        metavar="{on,off,auto}",
        help="--method spiral: choose among the search's model, output error and "
        "the integrated-noise fit by blocked folds of the estimation part; auto "
        "only where the modes table flags a mode (default: the library's, off)",
    )
    p.add_argument(
        "--integrator",
        nargs="?",
        type=_integrator_count,
        const=1,
        default=0,
        metavar="K",
        help="the output integrates (K known poles at z = 1, default 1; 2 for "
        "the rig's hub angle from torque): --na counts them, the method "
        "estimates the other poles; with several --output columns one count "
        "each (2,1,0,0), outside the shared --na poles",
    )


def _add_search_options(p: argparse.ArgumentParser) -> None:
    """A search's size, budget and seed."""
    _add_points_option(p)
    p.add_argument(
        "--iterations",
        type=_positive_int,
        default=None,
        help="max iterations (default: 500 for the paper's searches and de; no "
        "cap for spiral, a NARX search or below a --budget)",
    )
    p.add_argument(
        "--budget",
        type=_positive_int,
        default=None,
        help="max cost evaluations (default: the method's own: 10,000 "
        "evaluations for spiral and every NARX search; the others stop at "
        "--iterations)",
    )
    p.add_argument(
        "--workers",
        type=_positive_int,
        default=None,
        metavar="N",
        help="--model rig: run the search's simulations on N processes, the "
        "same result bit for bit (default: 1, this process)",
    )
    _add_seed_option(p)
