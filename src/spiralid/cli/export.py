"""``spiralid export``: a model's transfer function for other tools."""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from .errors import UsageError
from .options import _add_output_options, _command, _HelpFormatter

# --to, and the suffix of the file each writes.
_SUFFIXES = {"tf": ".txt", "json": ".json", "npz": ".npz", "mat": ".mat"}
# The formats that are binary files, never standard output.
_FILES_ONLY = ("npz", "mat")

# The one line that loads a model.json in Python (docs/guide/outputs.md).
PYTHON_LOAD = 'IdentifiedModel.from_dict(json.load(open("model.json"))).to_control()'

_DESCRIPTION = f"""\
Write the transfer function of MODEL (a model.json written by `spiralid
identify` or `spiralid pareto`): H(z) = num(z) / den(z), the coefficients
in descending powers of z, with the sample time ts in seconds, as
scipy.signal.dlti(num, den, dt=ts) and MATLAB's tf(num, den, ts) take them.

  --to tf    H(z), num, den and ts as text (standard output, or --out FILE)
  --to json  {{"num": [...], "den": [...], "ts": ..., ...}} with the model's
             structure, method, input and output (standard output, or
             --out FILE.json)
  --to npz   NumPy arrays num, den and ts (--out FILE.npz; numpy.load)
  --to mat   MATLAB variables num, den and ts (--out FILE.mat; in MATLAB:
             load FILE.mat, then tf(num, den, ts))

A model estimated after --detrend works on the record less its offsets
(u_offset and y_offset in the JSON). To use model.json itself in Python:

  import json; from spiralid import IdentifiedModel
  {PYTHON_LOAD}

(python-control: pip install "spiralid[control]"; .to_dlti() for SciPy)."""


class _Formatter(argparse.RawDescriptionHelpFormatter, _HelpFormatter):
    """The description as written (its table and code line), the options'
    defaults shown."""


# How a family's model is named in export's refusals.
_FAMILY_NAMES = {"narx": "NARX", "polynomial-narx": "polynomial NARX"}


def _model(name: str):
    """The ARX model in `name`: a nonlinear model has no transfer function,
    another family's has no ARX coefficients, and one of several outputs
    has one per output."""
    from .validate import _read_model

    model, _, _ = _read_model(name)
    takes = (
        "export takes the single-output ARX models of `spiralid identify` and "
        "`spiralid pareto`"
    )
    family = model.structure.family
    kind = _FAMILY_NAMES.get(family, family)
    if not model.is_linear:
        raise UsageError(
            f"{name!r} is a {kind} model: it has no transfer function to export "
            f"({takes})"
        )
    if family != "arx":
        raise UsageError(f"{name!r} is a {kind} model, not an ARX one ({takes})")
    outputs = model.output_names
    if len(outputs) > 1:
        raise UsageError(
            f"{name!r} is a model of {len(outputs)} outputs "
            f"({', '.join(outputs)}) with one denominator; {takes} (in "
            "Python, SharedDenominatorModel.output_model(name) gives each output's)"
        )
    return model


def transfer_function(model) -> dict:
    """The JSON of ``--to json``: ``num`` and ``den`` of ``model.to_dlti()``
    (descending powers of z), ``ts`` and what the model is."""
    dlti = model.to_dlti()
    return {
        "num": [float(v) for v in dlti.num],
        "den": [float(v) for v in dlti.den],
        "ts": float(model.ts),
        "variable": "z",
        "powers": "descending",
        "structure": str(model.arx),
        "method": model.method,
        "input": model.input_name,
        "output": model.output_name,
        "input_unit": model.input_unit,
        "output_unit": model.output_unit,
        "u_offset": float(model.u_offset),
        "y_offset": float(model.y_offset),
        "stable": bool(model.is_stable),
    }


def _text(model, tf: dict, name: str) -> str:
    """``--to tf``: H(z) as eq. (9)-(10) print it, then the exact
    coefficients and the sample time."""
    units = ""
    if model.input_unit or model.output_unit:
        units = f" [{model.input_unit or '-'} -> {model.output_unit or '-'}]"
    return "\n".join(
        [
            f"{tf['structure']} by {tf['method']} from {name}: input "
            f"{tf['input']!r}, output {tf['output']!r}{units}",
            f"H(z) = {model.tf_string()}",
            f"num = {json.dumps(tf['num'])}",
            f"den = {json.dumps(tf['den'])}",
            f"ts = {tf['ts']!r}",
            "",
        ]
    )


def _target(args) -> tuple[str, str | None]:
    """--to (from --out's suffix when not given) and --out, checked
    against each other before the model is read."""
    fmt, out = args.to, args.out
    suffix = Path(out).suffix.lower() if out is not None else ""
    if fmt is None:
        by_suffix = {s: f for f, s in _SUFFIXES.items() if f != "tf"}
        fmt = by_suffix.get(suffix, "tf")
    if out is None:
        if fmt in _FILES_ONLY:
            raise UsageError(
                f"--to {fmt} writes a file: give --out FILE{_SUFFIXES[fmt]}"
            )
        return fmt, None
    if fmt != "tf" and suffix != _SUFFIXES[fmt]:
        raise UsageError(f"--out {out!r} must end in {_SUFFIXES[fmt]} for --to {fmt}")
    if fmt == "tf" and suffix in (".json", ".npz", ".mat"):
        raise UsageError(
            f"--to tf writes text, not {suffix}: give --to {suffix[1:]} or "
            "--out FILE.txt"
        )
    return fmt, out


def _write(fmt: str, model, tf: dict, path: Path, name: str) -> None:
    if fmt == "tf":
        path.write_text(_text(model, tf, name), encoding="utf-8")
    elif fmt == "json":
        path.write_text(json.dumps(tf, indent=2) + "\n", encoding="utf-8")
    elif fmt == "npz":
        import numpy as np

        with path.open("wb") as fh:
            np.savez(fh, num=np.array(tf["num"]), den=np.array(tf["den"]), ts=tf["ts"])
    else:
        from scipy.io import savemat

        # Row vectors, as MATLAB's tf(num, den, ts) takes them.
        with path.open("wb") as fh:
            savemat(fh, {"num": tf["num"], "den": tf["den"], "ts": tf["ts"]})


def run(args, argv: list[str]) -> int:
    fmt, out = _target(args)
    model = _model(args.model)
    tf = transfer_function(model)
    if out is None:
        text = _text(model, tf, args.model) if fmt == "tf" else json.dumps(tf, indent=2)
        try:
            print(text.rstrip("\n"), flush=True)
        except BrokenPipeError:
            # The reader had enough (`| head`): not an error. Standard output
            # goes to the null device so the interpreter's exit stays quiet.
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    from spiralid.outputs.atomic import OutputFile

    with OutputFile(out, args.force) as target:
        _write(fmt, model, tf, target.path, args.model)
        target.commit()
    if not args.quiet:
        print(f"wrote {out} ({fmt}: {model.arx}, ts = {model.ts:g} s)")
    return 0


def add_parser(sub) -> None:
    p = _command(
        sub,
        "export",
        "write a model's transfer function as text, JSON, NPZ or MAT",
        _DESCRIPTION,
        run,
        _Formatter,
    )
    p.add_argument(
        "model", help="a model.json written by `spiralid identify` or `spiralid pareto`"
    )
    p.add_argument(
        "--to",
        choices=list(_SUFFIXES),
        default=None,
        help="format (default: from --out's suffix, .json, .npz or .mat; else tf)",
    )
    _add_output_options(
        p,
        None,
        "file to write (default: none, standard output; needed by npz and mat)",
        "overwrite --out",
        metavar="FILE",
    )
