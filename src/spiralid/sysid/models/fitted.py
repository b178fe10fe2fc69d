"""What every fitted model holds beside its structure and parameters.

:class:`FittedModel` is the one fitted-model type: an ARX fit
(:class:`~spiralid.sysid.models.identified.IdentifiedModel`) and a NARX fit
(:class:`~spiralid.sysid.models.narx.NARXModel`) are both a
``FittedModel`` and share its provenance (how the model was estimated, on
what record), its result summary and its JSON form; each adds only what its
structure needs (ARX: poles, covariance, cancellations; NARX: the scaling
and the linear start). A model family is one structure module plus the
fitted model's few structure-specific fields. The record-wide part of the
provenance is :class:`Provenance`, which the model of several outputs
(:class:`~spiralid.sysid.models.shared.SharedDenominatorModel`) shares too,
with one output name, unit and offset per output instead of
``FittedModel``'s one.

Every structure declares the same protocol (:class:`~spiralid.sysid.ARX`,
:class:`~spiralid.sysid.NARX`, :class:`~spiralid.sysid.PolynomialNARX`):
``n_params``, ``is_linear`` and a ``to_dict`` of its own. Every fitted model,
of one output or several, implements
:class:`~spiralid.sysid.models.protocol.FittedModelProtocol` (``structure``,
``params``, ``simulate(u)``, ``predict(data)``, ``linear_part``,
``output_names``, ``output_model``, ``summary()``, ``to_dict()``; a linear
model ``modes`` and ``is_stable`` too);
:func:`~spiralid.sysid.models.files.load_model` reads any of them back.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from spiralid._checks import named_index, one_of

from . import _fields
from .arx import INITIAL_CONDITIONS

__all__ = ["FittedModel", "Provenance"]

# The scalars of an estimator's result that a model file keeps (a residual
# vector would bloat it by a record's worth of numbers).
_SUMMARY_KEYS = (
    "fun",
    "nit",
    "nfev",
    "status",
    "success",
    "message",
    "start",
    "safe_start",
    "accepted",
    "kept_linear",
)


@dataclass(kw_only=True, eq=False)
class Provenance:
    """How a model was estimated and on what record: what every fitted
    model holds, of one output or several.

    Attributes
    ----------
    method : str
        The estimation method (a name of
        :data:`~spiralid.sysid.estimation.core.estimators.METHODS`).
    predictor : {"simulation", "one-step"}
        The error the cost measured.
    initial : {"rest", "measured"}
        Initial condition of the cost's simulation (see
        :class:`~spiralid.sysid.PaperCost`).
    gain : float
        The cost's gain ``w`` of eq. (2) (NaN when unknown).
    penalty : float
        The cost's stability penalty, eq. (3).
    cost : float
        The paper's cost, eq. (2)-(3), of the parameters on the estimation
        record.
    result : OptimizeResult or None
        What the estimator returned; ``None`` after ``from_dict`` (the model
        file keeps its scalars).
    history : ndarray or None
        Best cost after each iteration of a search.
    timings : dict
        Wall times in seconds (``"total"`` and the phases').
    input_name, input_unit : str
        The record's input name and unit, for tables and figure labels.
    u_offset : float
        Offset removed from the input before estimation; ``spiralid
        validate`` removes the same from new data.
    fraction : float or None
        The share of the record that estimated the model (the CLI's
        ``--fraction``), when known.
    """

    method: str
    predictor: str = "simulation"
    initial: str = "rest"
    gain: float = float("nan")
    penalty: float = 1e6
    cost: float = float("nan")
    result: Any = None
    history: np.ndarray | None = None
    timings: dict = field(default_factory=dict)
    input_name: str = "u"
    input_unit: str = ""
    u_offset: float = 0.0
    fraction: float | None = None

    def _check_provenance(self) -> None:
        """The provenance's own checks (each model's ``__post_init__``
        calls it before its structure's)."""
        one_of(self.initial, "initial", INITIAL_CONDITIONS)

    def _provenance_dict(self) -> dict:
        """The provenance as a model file holds it (``to_dict`` adds the
        structure's own fields)."""
        return {
            "method": self.method,
            "predictor": self.predictor,
            "initial": self.initial,
            "gain": float(self.gain),
            "penalty": float(self.penalty),
            "cost": float(self.cost),
            "history": None
            if self.history is None
            else [float(v) for v in self.history],
            "timings": {k: float(v) for k, v in self.timings.items()},
            "input_name": self.input_name,
            "input_unit": self.input_unit,
            "u_offset": float(self.u_offset),
            "fraction": None if self.fraction is None else float(self.fraction),
            "result": result_summary(self.result),
        }

    @staticmethod
    def _provenance_fields(
        d: dict, methods, *, initial: str = "rest", penalty: float = 1e6
    ) -> dict:
        """The provenance read back from a model file: the keyword
        arguments of the constructor, each field checked by its name
        (`initial` and `penalty` are the defaults of files written before
        those fields existed; `methods` None takes any name)."""
        fraction = d.get("fraction")
        if fraction is not None:
            fraction = _fields.number(
                d, "fraction", "a number in (0, 1) or null", lambda v: 0 < v < 1
            )
        return dict(
            method=str(d["method"]) if methods is None else _fields.method(d, methods),
            predictor=d.get("predictor", "simulation"),
            initial=d.get("initial", initial),
            gain=_fields.gain(d),
            penalty=_fields.number(
                d, "penalty", "a finite number >= 0", _fields.nonneg, penalty
            ),
            cost=_fields.number(d, "cost", "a number", _fields.anything, math.nan),
            history=None if d.get("history") is None else np.asarray(d["history"]),
            timings=dict(d.get("timings", {})),
            input_name=d.get("input_name", "u"),
            input_unit=str(d.get("input_unit", "")),
            u_offset=_fields.number(
                d, "u_offset", "a finite number", _fields.finite, 0.0
            ),
            fraction=fraction,
        )


@dataclass(kw_only=True, eq=False)
class FittedModel(Provenance):
    """The provenance of a fitted model of one output, shared by every
    structure: :class:`Provenance` and the output's name, unit and offset.

    Attributes
    ----------
    method : str
        The estimation method (a name of
        :data:`~spiralid.sysid.estimation.core.estimators.METHODS`).
    predictor : {"simulation", "one-step"}
        The error the cost measured.
    initial : {"rest", "measured"}
        Initial condition of the cost's simulation (see
        :class:`~spiralid.sysid.PaperCost`).
    gain : float
        The cost's gain ``w`` of eq. (2) (NaN when unknown).
    penalty : float
        The cost's stability penalty, eq. (3).
    cost : float
        The paper's cost, eq. (2)-(3), of the parameters on the estimation
        record.
    result : OptimizeResult or None
        What the estimator returned; ``None`` after ``from_dict`` (the model
        file keeps its scalars).
    history : ndarray or None
        Best cost after each iteration of a search.
    timings : dict
        Wall times in seconds (``"total"`` and the phases').
    input_name, output_name, input_unit, output_unit : str
        The record's signal names and units, for tables and figure labels.
    u_offset, y_offset : float
        Offsets removed from the record before estimation; ``spiralid
        validate`` removes the same from new data.
    fraction : float or None
        The share of the record that estimated the model (the CLI's
        ``--fraction``), when known.
    """

    output_name: str = "y"
    output_unit: str = ""
    y_offset: float = 0.0

    @property
    def is_linear(self) -> bool:
        """Whether the structure is linear in the signals (ARX): the poles,
        modes and realisation tests of :func:`~spiralid.sysid.validate`
        apply; otherwise the higher-order correlation tests do."""
        return bool(self.structure.is_linear)

    @property
    def output_names(self) -> tuple[str, ...]:
        """The one output this model predicts (as a model of several
        outputs names each of its own)."""
        return (self.output_name,)

    def output_model(self, which: int | str = 0) -> FittedModel:
        """The model of output `which` (its name or 0): the model itself,
        which :func:`~spiralid.sysid.validate` validates as it is."""
        named_index(which, "which", self.output_names)
        return self

    def summary(self) -> str:
        """The model in a few lines: structure, method, cost, output and,
        for a linear model, stability and the transfer function."""
        lines = [
            f"{type(self).__name__} of {self.output_name!r} from "
            f"{self.input_name!r}: {self.structure}",
            f"method {self.method}, predictor {self.predictor}, "
            f"cost {self.cost:.6g}, ts {self.ts:g} s",
        ]
        if self.is_linear:
            lines.append(f"stable: {self.is_stable}")
            lines.append(self.tf_string())
        return "\n".join(lines)

    def _provenance_dict(self) -> dict:
        """The provenance as a model file holds it, the output's fields
        beside the input's."""
        d = super()._provenance_dict()
        mine = {
            "output_name": self.output_name,
            "output_unit": self.output_unit,
            "y_offset": float(self.y_offset),
        }
        return {k: d.get(k, mine.get(k)) for k in _FILE_ORDER}

    @staticmethod
    def _provenance_fields(
        d: dict, methods, *, initial: str = "rest", penalty: float = 1e6
    ) -> dict:
        """The provenance read back from a model file (see
        :meth:`Provenance._provenance_fields`), with the output's fields."""
        return dict(
            Provenance._provenance_fields(d, methods, initial=initial, penalty=penalty),
            output_name=d.get("output_name", "y"),
            output_unit=str(d.get("output_unit", "")),
            y_offset=_fields.number(
                d, "y_offset", "a finite number", _fields.finite, 0.0
            ),
        )


# The order of a one-output model file's provenance keys (as written before
# the record-wide part became a base of its own).
_FILE_ORDER = (
    "method", "predictor", "initial", "gain", "penalty", "cost", "history",
    "timings", "input_name", "output_name", "input_unit", "output_unit",
    "u_offset", "y_offset", "fraction", "result",
)  # fmt: skip


def result_summary(res) -> dict | None:
    """The scalars of an estimator's result (an ``OptimizeResult`` or a
    plain mapping), JSON-safe; None without a result."""
    if res is None:
        return None
    mapping = isinstance(res, Mapping)
    out = {}
    for k in _SUMMARY_KEYS:
        if not (k in res if mapping else hasattr(res, k)):
            continue
        v = res[k] if mapping else getattr(res, k)
        if np.ndim(v) == 0:
            out[k] = v.item() if isinstance(v, np.generic) else v
    return out
