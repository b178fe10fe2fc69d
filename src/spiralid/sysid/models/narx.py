"""NARX models: a nonlinear map of past outputs and inputs.

``y(t) = F(y(t-1)..y(t-ny), u(t-nk)..u(t-nk-nu+1)) + e(t)``

Two maps are built:

* :class:`NARX`: a multilayer perceptron with one hidden layer
  (``hidden=(h,)``), an activation (``"tanh"``, ``"logistic"`` or
  ``"linear"``) and, by default, a linear bypass beside the network
  (``linear=True``: ``F = l^T phi + v^T sigma(W phi + b) + c``). The bypass is
  the ARX model, so a network whose output weights are zero is exactly the
  least-squares ARX and training starts from it (see
  :mod:`spiralid.sysid.estimation.narx.training`).
* :class:`PolynomialNARX`: a sum of monomials of the regressors up to
  ``degree`` whose terms are chosen by forward-regression orthogonal least
  squares (Billings, *Nonlinear System Identification*, Wiley, 2013, ch. 3),
  the classical baseline.

Signals are scaled before they reach the map (:class:`Scaling`: input and
output minus their estimation-record mean, over their standard deviation),
so the weights of one record are comparable with another's and a
metaheuristic's box need not depend on units. ``integrator=True`` (the
hub angle) makes the map predict the output's increment from past
increments, ``y(t) = y(t-1) + F(dy(t-1)..dy(t-ny), u...)``: the NARX
analogue of ARX's known pole at z = 1.

Free run and one-step prediction run on the scaled signals in compiled
loops (Numba), vectorised over a population of parameter vectors for the
searches. "From rest" means every signal is zero (in physical units)
before ``t = 0``, as for ARX; "from measured samples" takes the first
``max_lag`` measured outputs as the initial history.

This module holds the fitted model, :class:`NARXModel`, and is the public
path of the structures: :class:`NARX` lives in :mod:`.neural_narx`,
:class:`PolynomialNARX` in :mod:`.polynomial_narx`, what both share
(:class:`Scaling`, the lags and regressors) in :mod:`.narx_lags` and their
compiled loops in :mod:`._narx_kernels`.
"""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass

import numpy as np

from ..data import IOData, single_output_record
from ..signals import check_signal
from . import _fields
from .fitted import FittedModel
from .narx_lags import Scaling
from .neural_narx import ACTIVATIONS, NARX
from .polynomial_narx import PolynomialNARX

__all__ = [
    "ACTIVATIONS",
    "NARX",
    "NARXModel",
    "PolynomialNARX",
    "Scaling",
]


@dataclass(eq=False)
class NARXModel(FittedModel):
    """An estimated NARX model: structure, parameters, scaling and provenance
    (a :class:`~spiralid.sysid.models.fitted.FittedModel` of a NARX
    structure).

    What :func:`spiralid.sysid.identify` returns for a :class:`NARX` or
    :class:`PolynomialNARX` structure. A nonlinear model has no poles, so
    neither ``is_stable`` nor ``modes``: whether its free run stays bounded
    is what :func:`~spiralid.sysid.validate` reports (``diverged``).

    Attributes
    ----------
    params : ndarray
        The parameter vector (weights, or polynomial coefficients).
    structure : NARX or PolynomialNARX
        The structure.
    scaling : Scaling
        The signals' scaling.
    ts : float
        Sample time (s).
    method : str
        Estimation method.
    predictor : {"simulation", "one-step"}
        The error the cost measured.
    initial : {"rest", "measured"}
        Start of the free run the cost measured.
    cost : float
        Estimation cost (the paper's eq. (2) with gain ``100 sqrt(K) /
        rms(y)``: the error's RMS in percent of the output's).
    result : OptimizeResult or None
        The estimator's result.
    history : ndarray or None
        Best cost per iteration of a search.
    timings : dict
        Wall times (s).
    input_name, output_name, input_unit, output_unit : str
        Signal names and units.
    u_offset, y_offset : float
        Offsets removed before estimation (the record's, as for ARX).
    fraction : float or None
        The share of the record that estimated the model, when known.
    gain, penalty : float
        The cost's gain and stability penalty.
    linear_params : ndarray or None
        The linear start: the parameters of this structure that equal the
        linear (ARX) model training started from, network outputs zero
        (None for a structure without the bypass, or a polynomial NARX).
    linear_model : str
        What the linear start is, e.g. ``"ARX(9, 8, 0), integrator=2, by
        spiral"``.
    """

    params: np.ndarray
    structure: NARX | PolynomialNARX
    scaling: Scaling
    ts: float
    _: KW_ONLY
    penalty: float = 0.0
    linear_params: np.ndarray | None = None
    linear_model: str = ""

    def __post_init__(self) -> None:
        self._check_provenance()
        self.params = np.asarray(self.params, dtype=float)

    @property
    def linear_start(self) -> NARXModel | None:
        """The linear model training started from, as a NARXModel of the
        same structure (network outputs zero), or None without one."""
        if self.linear_params is None:
            return None
        return NARXModel(
            params=np.asarray(self.linear_params, dtype=float),
            structure=self.structure,
            scaling=self.scaling,
            ts=self.ts,
            method=self.method,
            predictor=self.predictor,
            initial=self.initial,
        )

    @property
    def linear_part(self) -> NARXModel | None:
        """The linear model inside this one (:attr:`linear_start`), or None
        for a structure without a linear bypass."""
        return self.linear_start

    def simulate(self, u, y0=None) -> np.ndarray:
        """Free run over the input `u` from rest, or with ``y0`` (the measured
        output record) from its first ``max_lag`` samples.

        Parameters
        ----------
        u : array_like or IOData
            Input (an IOData contributes its ``u``).
        y0 : array_like, optional
            Measured output; its first ``max_lag`` samples start the run and
            are returned unchanged.

        Returns
        -------
        ndarray, shape (N,)
        """
        u = u.u if isinstance(u, IOData) else check_signal(u, "u")
        return simulate_structure(
            self.structure,
            self.params,
            self.scaling,
            u,
            None if y0 is None else check_signal(y0, "y0"),
        )

    def predict(self, data: IOData) -> np.ndarray:
        """One-step-ahead prediction from the measured past (rest before 0).

        Parameters
        ----------
        data : IOData
        """
        single_output_record(data, "a NARX model")
        phi, _ = self.structure.regressors(data.u, data.y, self.scaling)
        z = self.structure.evaluate(self.params, phi)
        s = self.scaling
        if self.structure.integrator:
            prev = np.r_[0.0, data.y[:-1]]
            return prev + z * s.y_scale
        return s.y_shift + s.y_scale * z

    def to_dict(self, *, timings: bool = True) -> dict:
        """A JSON-safe dictionary; ``NARXModel.from_dict`` reads it back.

        Parameters
        ----------
        timings : bool
            Include the wall times.
        """
        st = self.structure
        if isinstance(st, NARX):
            sd = {
                "type": "mlp",
                "ny": st.ny,
                "nu": st.nu,
                "nk": st.nk,
                "hidden": list(st.hidden),
                "activation": st.activation,
                "linear": st.linear,
                "integrator": st.integrator,
            }
        else:
            sd = {
                "type": "polynomial",
                "ny": st.ny,
                "nu": st.nu,
                "nk": st.nk,
                "degree": st.degree,
                "integrator": st.integrator,
                "terms": [list(t) for t in st.terms],
                "term_names": st.term_names(),
            }
        out = {
            "model": "narx",
            "structure": sd,
            "params": [float(v) for v in self.params],
            "scaling": {
                k: float(getattr(self.scaling, k))
                for k in ("u_shift", "u_scale", "y_shift", "y_scale")
            },
            "ts": float(self.ts),
            **self._provenance_dict(),
            "linear_start": None
            if self.linear_params is None
            else {
                "model": self.linear_model,
                "params": [float(v) for v in self.linear_params],
            },
        }
        if not timings:
            del out["timings"]
        return out

    @classmethod
    def from_dict(cls, d: dict) -> NARXModel:
        """Rebuild from :meth:`to_dict` output (``result`` is not restored);
        a field that is missing or out of range (``ts <= 0``, an unknown
        method, a zero scale...) raises a ValueError that names it.

        Parameters
        ----------
        d : dict
        """
        if not isinstance(d, dict) or d.get("model") != "narx":
            raise ValueError("a NARX model must be a JSON object with model 'narx'")
        try:
            sd = dict(d["structure"])
            kind = sd.pop("type")
            if kind == "mlp":
                st = NARX(
                    sd["ny"],
                    sd["nu"],
                    sd["nk"],
                    hidden=tuple(sd["hidden"]),
                    activation=sd["activation"],
                    linear=sd["linear"],
                    integrator=sd["integrator"],
                )
            elif kind == "polynomial":
                terms = tuple(tuple(t) for t in sd["terms"])
                st = PolynomialNARX(
                    sd["ny"],
                    sd["nu"],
                    sd["nk"],
                    degree=sd["degree"],
                    n_terms=len(terms),
                    integrator=sd["integrator"],
                    terms=terms,
                )
            else:
                raise ValueError(
                    f"field 'structure.type' must be 'mlp' or 'polynomial'; "
                    f"got {kind!r}"
                )
            params = np.asarray(d["params"], dtype=float)
            if params.shape != (st.n_params,) or not np.all(np.isfinite(params)):
                raise ValueError(
                    f"field 'params' must hold {st.n_params} finite numbers for {st}"
                )
            scaling = d["scaling"]
            if not isinstance(scaling, dict):
                raise ValueError(
                    f"field 'scaling' must be an object; got {scaling!r:.80}"
                )
            # The scales divide the signals: zero, negative or non-finite
            # ones would only fail (or mislead) at the first simulation.
            sc = Scaling(
                **{
                    k: _fields.number(scaling, k, allowed, ok, where="scaling.")
                    for k, allowed, ok in (
                        ("u_shift", "a finite number", _fields.finite),
                        ("u_scale", "a number > 0", _fields.positive),
                        ("y_shift", "a finite number", _fields.finite),
                        ("y_scale", "a number > 0", _fields.positive),
                    )
                }
            )
            return cls(
                params=params,
                structure=st,
                scaling=sc,
                ts=_fields.number(d, "ts", "a number > 0", _fields.positive),
                **cls._provenance_fields(d, _narx_methods(), penalty=0.0),
                **_linear_start(d.get("linear_start"), st),
            )
        except KeyError as exc:
            raise ValueError(f"the field {exc.args[0]!r} is missing") from None

    def __repr__(self) -> str:
        return (
            f"NARXModel({self.structure}, method={self.method!r}, "
            f"predictor={self.predictor!r}, cost={self.cost:.6g})"
        )


def _linear_start(field, structure) -> dict:
    """NARXModel's linear-start fields from a model file's
    ``"linear_start"`` (absent or null in files written before it)."""
    if field is None:
        return {}
    if not isinstance(field, dict):
        raise ValueError(f"field 'linear_start' must be an object; got {field!r:.80}")
    params = np.asarray(field.get("params"), dtype=float)
    if params.shape != (structure.n_params,) or not np.all(np.isfinite(params)):
        raise ValueError(
            f"field 'linear_start.params' must hold {structure.n_params} finite "
            f"numbers for {structure}"
        )
    return {"linear_params": params, "linear_model": str(field.get("model", ""))}


def _narx_methods() -> tuple[str, ...]:
    """The methods a NARX model file may name (the names only: the models
    stage imports no estimator; tests/test_layout.py)."""
    from spiralid.choices import METHOD_NAMES

    return METHOD_NAMES


def simulate_structure(structure, params, scaling: Scaling, u, y0=None):
    """Free run of `structure` with `params` (one vector, or rows for the
    MLP) over `u`: from rest, or from the first ``max_lag`` samples of the
    measured output `y0`, which are returned unchanged."""
    ulag = structure.input_lags(u, scaling)
    if y0 is None:
        t0, hist, ystart = structure._history(None, scaling, "rest")
    else:
        if y0.size != u.size:
            raise ValueError(
                f"`y0` must have the input's length {u.size}; got {y0.size}"
            )
        t0, hist, ystart = structure._history(y0, scaling, "measured")
    z = structure.free_run_scaled(params, ulag[t0:], hist)
    y = structure._unscale(z, scaling, ystart)
    if t0 == 0:
        return y
    head = np.broadcast_to(y0[:t0], (*y.shape[:-1], t0))
    return np.concatenate([head, y], axis=-1)
