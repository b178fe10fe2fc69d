"""The fitted neural state-space model: :class:`NeuralStateSpaceModel`
(structure in :mod:`.neural_state_space`)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import ClassVar

import numpy as np

from ..data import IOData
from .neural_state_space import NeuralStateSpace

__all__ = ["NeuralStateSpaceModel"]

# What the model keeps of its record (IOData's fields of the same names).
_RECORD = ("input_name", "input_unit", "output_unit", "u_offset", "y_offset")


def _inputs(u) -> np.ndarray:
    return np.asarray(u.u if isinstance(u, IOData) else u, dtype=float).ravel()


@dataclass
class NeuralStateSpaceModel:
    """A neural state-space model fitted to a record.

    Attributes
    ----------
    structure : NeuralStateSpace
        The structure fitted.
    params : ndarray, shape (structure.n_params,)
        Every parameter, the encoder's included.
    linear_params : ndarray or None
        The linear start's parameters (networks' output weights zero).
    u_scale, y_scale : float
        The scales the model's signals are divided by.
    ts : float
        The record's sample time.
    method : str
        The method that fitted the linear start.
    cost : float
        RMS of the free run's error from rest over the held-back samples,
        in the output's unit (NaN with nothing held back).
    result : dict
        What the training did: ``kept_linear`` (the linear start scored
        better on the held-back samples and was kept), ``linear_cost``
        (its held-back RMS), ``schedule`` (``[[horizon, iterations,
        held-back RMS], ...]``), ``nfev``.
    linear_model : str
        How the linear start was fitted.
    output_name : str
        The output's name.
    input_name, input_unit, output_unit : str
        The record's names and units.
    u_offset, y_offset : float
        Offsets removed from the record's signals before the fit.
    """

    #: What :attr:`cost` is, for summaries (every other family's is eq. 2).
    cost_label: ClassVar[str] = "held-back free-run RMS"

    structure: NeuralStateSpace
    params: np.ndarray
    ts: float
    method: str
    u_scale: float = 1.0
    y_scale: float = 1.0
    linear_params: np.ndarray | None = None
    cost: float = float("nan")
    result: dict = field(default_factory=dict)
    linear_model: str = ""
    output_name: str = "y"
    input_name: str = "u"
    input_unit: str = ""
    output_unit: str = ""
    u_offset: float = 0.0
    y_offset: float = 0.0

    def __post_init__(self) -> None:
        self.params = self.structure._params(self.params)
        if self.linear_params is not None:
            self.linear_params = self.structure._params(
                self.linear_params, "linear_params"
            )

    @property
    def timings(self) -> dict:
        """Wall time of the fit in seconds (``"total"``; empty after a
        model file, which keeps none)."""
        seconds = self.result.get("seconds")
        return {} if seconds is None else {"total": float(seconds)}

    # -- the protocol -----------------------------------------------------------

    @property
    def is_linear(self) -> bool:
        """False: the networks make it nonlinear (the linear start too is
        read as this family's model, not as a transfer function)."""
        return False

    @property
    def linear_start(self) -> NeuralStateSpaceModel | None:
        """The linear start as a model of this family (None after a file
        without it)."""
        if self.linear_params is None:
            return None
        return replace(
            self, params=self.linear_params, result={"kept_linear": True}, cost=np.nan
        )

    @property
    def linear_part(self) -> NeuralStateSpaceModel | None:
        """The linear start (:attr:`linear_start`)."""
        return self.linear_start

    @property
    def output_names(self) -> tuple[str, ...]:
        return (self.output_name,)

    def output_model(self, which: int | str) -> NeuralStateSpaceModel:
        """The model itself (one output)."""
        if which not in (0, self.output_name):
            raise ValueError(
                f"`which` must be 0 or {self.output_name!r}; got {which!r}"
            )
        return self

    def simulate(self, u, y0=None) -> np.ndarray:
        """The free run over `u` (an ``IOData`` gives its ``u``), shape
        (N,): from rest (the zero state) by default; with measured outputs
        `y0` (at least ``structure.window`` of them), the first ``window``
        samples are `y0`'s and the run continues from the encoder's state.

        Parameters
        ----------
        u : array_like or IOData
        y0 : array_like, optional
        """
        u = _inputs(u)
        us = u / self.u_scale
        if y0 is None:
            return self.y_scale * self.structure.free_run(self.params, us)
        y0 = np.asarray(y0, dtype=float).ravel()
        w = self.structure.window
        if y0.size < w or u.size < w:
            raise ValueError(
                f"`y0` and `u` must have at least window = {w} samples; got "
                f"{y0.size} and {u.size}"
            )
        ys = np.zeros(u.size)
        ys[:w] = y0[:w] / self.y_scale
        z = self.structure.regressors(ys, us, [w])[0]
        x0 = self.structure.split(self.params)["E"] @ z
        run = self.structure.free_run(self.params, us[w:], x0)
        return np.r_[y0[:w], self.y_scale * run]

    def predict(self, data: IOData) -> np.ndarray:
        """The one-step prediction: at each sample past the window, one
        step from the encoder's state of the measured samples before it;
        the first ``window`` samples are the free run's."""
        u = _inputs(data)
        y = np.asarray(data.y, dtype=float).ravel()
        st, w = self.structure, self.structure.window
        out = self.simulate(u)
        if u.size <= w:
            return out
        us, ys = u / self.u_scale, y / self.y_scale
        t = np.arange(w, u.size)
        blocks = st.split(self.params)
        X = st.regressors(ys, us, t) @ blocks["E"].T
        for k, x0 in zip(t, X, strict=True):
            out[k] = self.y_scale * st.free_run(self.params, us[k : k + 1], x0)[0]
        return out

    def summary(self) -> str:
        """Structure, method, held-back RMS and what the training did."""
        res = self.result
        kept = " (the linear start was kept)" if res.get("kept_linear") else ""
        return "\n".join(
            [
                f"{self.structure}",
                f"linear start: {self.linear_model or '?'}",
                f"method {self.method}, held-back free-run RMS {self.cost:.6g}"
                f" {self.output_unit}".rstrip()
                + f" (linear start {res.get('linear_cost', np.nan):.6g}){kept}",
                f"ts = {self.ts:g} s",
            ]
        )

    def to_dict(self, *, timings: bool = True) -> dict:
        """The ``model.json`` form.

        Parameters
        ----------
        timings : bool
            Accepted as every model's ``to_dict`` takes it (this model keeps
            no timings).
        """
        res = {
            k: v
            for k, v in self.result.items()
            if k in ("kept_linear", "linear_cost", "schedule", "nfev")
        }
        return dict(
            model="neural-state-space",
            structure=self.structure.to_dict(),
            params=self.params.tolist(),
            linear_params=None
            if self.linear_params is None
            else self.linear_params.tolist(),
            u_scale=float(self.u_scale),
            y_scale=float(self.y_scale),
            ts=float(self.ts),
            method=str(self.method),
            cost=float(self.cost),
            result=res,
            linear_model=self.linear_model,
            output_name=self.output_name,
            **{name: getattr(self, name) for name in _RECORD},
        )

    @classmethod
    def from_dict(cls, d: dict) -> NeuralStateSpaceModel:
        """The model :meth:`to_dict` wrote.

        Parameters
        ----------
        d : dict
        """
        if not isinstance(d, dict) or d.get("model") != "neural-state-space":
            raise ValueError(
                "a neural state-space model file must have 'model': "
                "'neural-state-space'"
            )
        try:
            lin = d.get("linear_params")
            return cls(
                structure=NeuralStateSpace.from_dict(d["structure"]),
                params=np.asarray(d["params"], dtype=float),
                linear_params=None if lin is None else np.asarray(lin, dtype=float),
                u_scale=float(d["u_scale"]),
                y_scale=float(d["y_scale"]),
                ts=float(d["ts"]),
                method=str(d["method"]),
                cost=float(d.get("cost", np.nan)),
                result=dict(d.get("result", {})),
                linear_model=str(d.get("linear_model", "")),
                output_name=str(d.get("output_name", "y")),
                **{name: d[name] for name in _RECORD if name in d},
            )
        except KeyError as missing:
            raise ValueError(
                f"neural state-space model file: field {missing} is missing"
            ) from None

    def __repr__(self) -> str:
        return f"NeuralStateSpaceModel({self.structure}; {self.method})"
