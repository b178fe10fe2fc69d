"""Validation of a model of several outputs: each output's fit and a joint
fit, in the one :class:`~spiralid.sysid.validation.result.Validation`.

:func:`~spiralid.sysid.validate` validates a model of several outputs
(e.g. a :class:`~spiralid.sysid.models.shared.SharedDenominatorModel`)
output by output: each output's model (``model.output_model(name)``, for a
shared denominator its transfer function ``B_i / A``) on that output of
the record, so every test and figure of one output holds for each. The
result is a :class:`Validation` whose ``outputs`` holds each output's and
whose ``fit_percent`` is the joint fit:

    joint fit = 100 (1 - sqrt(mean_i (1 - fit_i / 100)^2)),

the normalised RMS error over the outputs, each in its own scale (equal to
the fit of a single output when there is one).
"""

from __future__ import annotations

import numpy as np

from ..data import IOData

__all__ = [
    "check_output_records",
    "joint_dict",
    "joint_fit",
    "joint_summary",
    "mac_text",
]


def joint_fit(fits) -> float:
    """The joint fit (%) of per-output fits (%): ``100 (1 - sqrt(mean_i (1
    - fit_i / 100)^2))``.

    Parameters
    ----------
    fits : array_like
        Each output's fit, in percent.

    Examples
    --------
    >>> joint_fit([90.0]), round(joint_fit([90.0, 70.0]), 3)
    (90.0, 77.639)
    """
    miss = 1.0 - np.asarray(fits, dtype=float) / 100.0
    return float(100.0 * (1.0 - np.sqrt(np.mean(miss**2))))


def check_output_records(model, data, warmup) -> None:
    """`data` and `warmup` (None: none) hold every output of `model`, by
    name; a one-line ValueError naming the record and the missing outputs
    otherwise."""
    for name, record in (("data", data), ("warmup", warmup)):
        if record is None:
            continue
        if not isinstance(record, IOData):
            raise TypeError(f"`{name}` must be an IOData; got {type(record).__name__}")
        missing = [o for o in model.output_names if o not in record.output_names]
        if missing:
            raise ValueError(
                f"`{name}` must hold the model's outputs {model.output_names}; "
                f"missing {missing}"
            )


def joint_summary(v, modes: bool = True) -> str:
    """The plain-text table of a validation of several outputs `v`: each
    output's fit, the joint fit and (unless `modes` is False) the model's
    modes."""
    title = f"Validation of {v.label}" if v.label else "Validation"
    width = max(len(n) for n in v.outputs)
    lines = [title, "-" * max(len(title), 40)]
    for name, one in v.outputs.items():
        flag = " (diverged)" if one.diverged else ""
        lines.append(f"fit % of {name:<{width}}  {one.fit_percent:8.2f}{flag}")
    lines.append(f"joint fit %{' ' * (width - 2)}  {v.fit_percent:8.2f}")
    if modes and v.mode_table is not None:
        lines += ["", "Shared modes (share of each output's peaks)", str(v.mode_table)]
    shapes = v.mode_shapes
    if modes and shapes is not None and len(shapes):
        lines += ["", "Mode shapes over the outputs (from the residues)", str(shapes)]
        lines += ["", "MAC between the modes", mac_text(shapes.auto_mac)]
    return "\n".join(lines)


def mac_text(matrix) -> str:
    """A MAC matrix as plain text, modes numbered from 1.

    Parameters
    ----------
    matrix : array_like, shape (m, k)
        MAC values in [0, 1].

    Examples
    --------
    >>> print(mac_text([[1.0, 0.25], [0.25, 1.0]]))
    mode      1      2
       1  1.000  0.250
       2  0.250  1.000
    """
    matrix = np.asarray(matrix, dtype=float)
    head = "mode" + "".join(f"{k + 1:>7}" for k in range(matrix.shape[1]))
    rows = [
        f"{i + 1:>4}" + "".join(f"{v:7.3f}" for v in row)
        for i, row in enumerate(matrix)
    ]
    return "\n".join([head, *rows])


def joint_dict(v) -> dict:
    """The JSON form of a validation of several outputs `v`."""
    return {
        "label": v.label,
        "joint_fit_percent": v.fit_percent,
        "outputs": {name: one.to_dict() for name, one in v.outputs.items()},
        "modes": None if v.mode_table is None else v.mode_table.to_dict(),
        "shapes": None if v.mode_shapes is None else v.mode_shapes.to_dict(),
    }
