"""``spiralid validate``: validate a saved model on a record."""

from __future__ import annotations

import json
from pathlib import Path

from .errors import UsageError
from .options import (
    _add_data_options,
    _add_detrend_option,
    _add_fraction_option,
    _add_output_options,
    _command,
    _detrended,
    _listing,
    _load_data,
    _open_folder,
    _progress,
    _save_figures,
)


def _read_model(name: str):
    """The model file, whether it records its preprocessing (files
    written before it did only know --detrend from the user) and whether
    it records the names of its input and output."""
    from spiralid.sysid.models.files import load_model

    path = Path(name)
    if path.is_dir():
        raise UsageError(f"model file {name!r} is a folder, not a model.json")
    if not path.is_file():
        raise UsageError(f"model file {name!r} does not exist")
    try:
        fields = json.loads(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise UsageError(f"model file {name!r} is not UTF-8 text") from None
    except ValueError as exc:
        raise UsageError(
            f"{name!r} is not a valid spiralid model file (not JSON: {exc})"
        ) from None
    try:
        model = load_model(fields)
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        message = " ".join(str(exc).split()).replace("`", "'")
        raise UsageError(
            f"{name!r} is not a valid spiralid model file ({message})"
        ) from None
    named = "output_name" in fields or "output_names" in fields
    return model, "u_offset" in fields, named


def _outputs_of(model) -> list[str]:
    """The outputs a model was estimated on: one, or several of a shared
    denominator."""
    return list(model.output_names)


def _offsets_of(model) -> tuple[float, ...]:
    """The output offsets the model file records, one per output."""
    several = getattr(model, "y_offsets", None)
    if several is not None:
        return tuple(several)
    return tuple(model.output_model(name).y_offset for name in model.output_names)


def _inputs_of(model) -> list[str]:
    """The inputs a model was estimated on: one, or several of a shared
    denominator."""
    return list(getattr(model, "input_names", (model.input_name,)))


def _names_in(name: str) -> set[str] | None:
    """The names DATA's columns (a CSV header's, with or without their unit)
    or variables (NPZ, MAT) go by; None for a shipped data set, a file
    without a header, or one that cannot be read (reading it says why)."""
    import csv

    from spiralid.sysid.readers import _is_number, _split_unit

    path = Path(name)
    suffix = path.suffix.lower()
    try:
        if suffix == ".csv":
            with path.open(newline="", encoding="utf-8-sig") as fh:
                header = [c.strip() for c in next((r for r in csv.reader(fh) if r), [])]
            if not header or all(_is_number(c) for c in header):
                return None
            return set(header) | {_split_unit(c)[0] for c in header}
        if suffix == ".npz":
            import numpy as np

            with path.open("rb") as fh:
                if fh.read(4) != b"PK\x03\x04":
                    return None
            # Only the archive's member names: nothing is unpickled.
            with np.load(path, allow_pickle=False) as z:
                return set(z.files)
        if suffix == ".mat":
            from scipy.io import whosmat

            return {n for n, *_ in whosmat(path)}
    except (OSError, ValueError, TypeError, NotImplementedError, EOFError):
        return None
    return None


def _columns_of_the_model(args, model) -> None:
    """--input and --output, when not given, from the names the model file
    records: another column of the same file would be scored silently (a
    fit near 0 % for the wrong signal)."""
    from spiralid import datasets

    if not Path(args.data).exists() and args.data in datasets.NAMES:
        return  # a shipped data set has one input and one output
    names = _names_in(args.data)
    if names is None:
        return
    outputs = _outputs_of(model)
    inputs = _inputs_of(model)
    wanted = {
        "input": inputs if args.input is None else [],
        "output": outputs if args.output is None else [],
    }
    missing = [v for vs in wanted.values() for v in vs if v not in names]
    if missing:
        kind = "column" if Path(args.data).suffix.lower() == ".csv" else "variable"
        plural = "s" if len(outputs) > 1 else ""
        order = ", in the model's order" if len(outputs) > 1 else ""
        raise UsageError(
            f"the model was estimated on input {', '.join(map(repr, inputs))} and "
            f"output{plural} {', '.join(map(repr, outputs))}, but {args.data!r} has "
            f"no {kind} {' or '.join(map(repr, missing))}; give --input and "
            f"--output with the {kind}s that hold them{order}"
        )
    if wanted["input"]:
        args.input = inputs if len(inputs) > 1 else inputs[0]
    if wanted["output"]:
        args.output = outputs if len(outputs) > 1 else outputs[0]


def _outputs_as_the_model(data, model):
    """`data`'s outputs in the model's order and under its names: matched
    by name where the record carries the model's names (in any order), or
    taken in the order --output gave them where the columns were renamed.
    Every per-output field (offset, unit) then lines up with the model's."""
    wanted = _outputs_of(model)
    have = data.output_names
    if len(wanted) == 1 == len(have):
        return data
    if set(wanted) <= set(have):
        return data.select_outputs(wanted)
    if len(have) == len(wanted) and not set(have) & set(wanted):
        return data.select_outputs(have, rename=wanted)
    raise UsageError(
        f"--output must name the model's {len(wanted)} outputs "
        f"({', '.join(wanted)}): by those names, or {len(wanted)} other columns "
        f"in that order; got {', '.join(have)}"
    )


def _prepared_as_the_model(data, model, recorded: bool, args):
    """`data` shifted by the offsets the model was estimated with, as its
    file records them (with or without `--detrend`); for files that record
    nothing, `--detrend` removes the means of the part before `--fraction`."""
    if not recorded:
        return _detrended(data, args.fraction) if args.detrend else data
    offsets = _offsets_of(model)
    u_offsets = getattr(model, "u_offsets", (model.u_offset,))
    if not any(u_offsets) and not any(offsets):
        if args.detrend:
            raise UsageError(
                "--detrend does not apply: the model was estimated without it"
            )
        return data
    from dataclasses import replace

    import numpy as np

    y_offset = tuple(a + b for a, b in zip(data.y_offsets, offsets, strict=True))
    u_offset = tuple(a + b for a, b in zip(data.u_offsets, u_offsets, strict=True))
    return replace(
        data,
        u=data.u - (u_offsets[0] if data.u.ndim == 1 else np.asarray(u_offsets)),
        y=data.y - (offsets[0] if data.y.ndim == 1 else np.asarray(offsets)),
        u_offset=u_offset[0] if data.u.ndim == 1 else u_offset,
        y_offset=y_offset[0] if data.y.ndim == 1 else y_offset,
    )


def _validation(model, data, warm):
    """The model's validation on `data` (after `warm`): one output's, or
    each output's and the joint fit of a shared denominator."""
    from spiralid.sysid import validate

    return validate(model, data, warmup=warm, label=model.method)


def _figures(v) -> dict:
    """The validation's figures by file stem (each output's, prefixed by
    its name, for several outputs)."""
    if v.outputs is None:
        return v.plot()
    from spiralid.report.shared_output import output_stems

    stems = output_stems(v.outputs)
    return {
        f"{stems[name]}_{kind}": fig
        for name, one in v.outputs.items()
        for kind, fig in one.plot().items()
    }


def run(args, argv: list[str]) -> int:
    with _progress(args) as progress:
        progress.phase("load", "loading the model and the data")
        model, recorded, named = _read_model(args.model)
        if named:
            _columns_of_the_model(args, model)
        # The data's own sample time wins; validate() refuses one that
        # differs from the model's. Only a file without one borrows the
        # model's.
        data = _outputs_as_the_model(_load_data(args, default_ts=model.ts), model)
        data = _prepared_as_the_model(data, model, recorded, args)
        if args.fraction is not None:
            warm, data = data.split(args.fraction)
        else:
            warm = None
        if args.out is None:
            progress.phase("validation", "validating")
            v = _validation(model, data, warm)
            written = None
        else:
            with _open_folder(args.out, args.force) as folder:
                progress.phase("validation", "validating")
                v = _validation(model, data, warm)
                progress.phase("writing", "writing files and figures")
                (folder.path / "validation.json").write_text(
                    json.dumps(v.to_dict(), indent=2)
                )
                (folder.path / "summary.txt").write_text(v.summary() + "\n")
                _save_figures(_figures(v), folder.path)
                written = folder.commit(last="validation.json")
    if not args.quiet:
        print(v.summary())
        if written is not None:
            print(f"\nwrote {_listing(written, args.out)}")
    return 0


_DESCRIPTION = (
    "Fit %, error range, residual tests, spectra, modes, stability and "
    "realisation tests of MODEL on DATA."
)


def add_parser(sub) -> None:
    p = _command(
        sub, "validate", "validate a saved model on a data file", _DESCRIPTION, run
    )
    p.add_argument("model", help="model.json written by `spiralid identify`")
    _add_data_options(p)
    _add_fraction_option(
        p,
        None,
        "run the model over the whole record but score only the part after "
        "this share (e.g. 2/3 for the validation third); default: score all",
    )
    _add_detrend_option(
        p,
        "; a model.json that records its offsets has them applied anyway, and "
        "one estimated without --detrend refuses it",
    )
    _add_output_options(
        p,
        None,
        "directory for validation.json, summary.txt and figures (default: "
        "none, only the summary is printed)",
    )
