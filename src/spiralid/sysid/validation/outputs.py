"""Validation of a model of several outputs: each output's fit and a joint
fit.

A :class:`~spiralid.sysid.models.shared.SharedDenominatorModel` is validated
output by output: each output's transfer function ``B_i / A``
(:meth:`~spiralid.sysid.models.shared.SharedDenominatorModel.output_model`)
through :func:`~spiralid.sysid.validate` on that output, so every test and
figure of one output holds for each. The joint fit combines them:

    joint fit = 100 (1 - sqrt(mean_i (1 - fit_i / 100)^2)),

the normalised RMS error over the outputs, each in its own scale (equal to
the fit of a single output when there is one).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..data import IOData
from ..models.shared import SharedDenominatorModel, SharedModes
from .validate import Validation, validate

__all__ = ["OutputsValidation", "joint_fit", "validate_outputs"]


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


@dataclass
class OutputsValidation:
    """Each output's :class:`Validation`, the joint fit and the modes.

    Parameters
    ----------
    outputs : dict of str to Validation
        Each output's validation, by name.
    joint_fit_percent : float
        :func:`joint_fit` of their fits.
    modes : SharedModes
        The model's shared modes with intervals and shares.
    label : str
        A name for the tables.
    """

    outputs: dict[str, Validation]
    joint_fit_percent: float
    modes: SharedModes
    label: str = ""

    def summary(self, modes: bool = True) -> str:
        """A plain-text table: each output's fit, the joint fit and (unless
        `modes` is False) the modes."""
        title = f"Validation of {self.label}" if self.label else "Validation"
        width = max(len(n) for n in self.outputs)
        lines = [title, "-" * max(len(title), 40)]
        for name, v in self.outputs.items():
            flag = " (diverged)" if v.diverged else ""
            lines.append(f"fit % of {name:<{width}}  {v.fit_percent:8.2f}{flag}")
        lines.append(f"joint fit %{' ' * (width - 2)}  {self.joint_fit_percent:8.2f}")
        if modes:
            lines += [
                "",
                "Shared modes (share of each output's peaks)",
                str(self.modes),
            ]
        return "\n".join(lines)

    def to_dict(self) -> dict:
        return {
            "label": self.label,
            "joint_fit_percent": self.joint_fit_percent,
            "outputs": {name: v.to_dict() for name, v in self.outputs.items()},
            "modes": self.modes.to_dict(),
        }


def validate_outputs(
    model: SharedDenominatorModel,
    data: IOData,
    *,
    warmup: IOData | None = None,
    label: str | None = None,
) -> OutputsValidation:
    """Validate a shared-denominator model on a record of its outputs.

    Parameters
    ----------
    model : SharedDenominatorModel
    data : IOData
        A record holding every output of `model` (by name; others are left
        out).
    warmup : IOData, optional
        The record before `data` (the estimation part), run through first,
        as :func:`~spiralid.sysid.validate`'s ``warmup``.
    label : str, optional
        A name for the tables; default the model's method.

    Returns
    -------
    OutputsValidation
    """
    if not isinstance(model, SharedDenominatorModel):
        raise ValueError(
            f"`model` must be a SharedDenominatorModel; got {type(model).__name__}"
        )
    for name, record in (("data", data), ("warmup", warmup)):
        if record is None:
            continue
        if not isinstance(record, IOData):
            raise ValueError(f"`{name}` must be an IOData; got {type(record).__name__}")
        missing = [o for o in model.output_names if o not in record.output_names]
        if missing:
            raise ValueError(
                f"`{name}` must hold the model's outputs {model.output_names}; "
                f"missing {missing}"
            )
    label = model.method if label is None else str(label)
    outputs = {
        name: validate(
            model.output_model(name),
            data.output(name),
            warmup=None if warmup is None else warmup.output(name),
            label=f"{label}, {name}",
        )
        for name in model.output_names
    }
    return OutputsValidation(
        outputs,
        joint_fit([v.fit_percent for v in outputs.values()]),
        model.modes,
        label,
    )
