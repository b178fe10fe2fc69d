"""The result of an identification: :class:`IdentifiedModel`."""

from __future__ import annotations

import math
from dataclasses import KW_ONLY, dataclass
from typing import Any

import numpy as np
from scipy import signal

from ..data import IOData
from . import _fields
from .arx import ARX
from .fitted import FittedModel, result_summary
from .modes import ModeTable, mode_table
from .polynomials import (
    deflate_integrator,
    integrator_count,
    is_stable_polynomial,
    max_pole_radius,
    with_integrator,
)

__all__ = ["IdentifiedModel"]

_MAX_COEFFICIENT = 1e150


def python_control():
    """The python-control module, an optional dependency, or an ImportError
    saying how to install it (the models' ``to_control``)."""
    try:
        import control
    except ImportError:
        raise ImportError(
            'to_control() needs python-control: pip install "spiralid[control]"'
        ) from None
    return control


@dataclass(eq=False)
class IdentifiedModel(FittedModel):
    """An estimated ARX model with how it was obtained: a
    :class:`~spiralid.sysid.models.fitted.FittedModel` of an ARX structure.

    Attributes
    ----------
    theta : ndarray, shape (p,)
        ``[a_1..a_na, b_0..b_(nb-1)]``.
    arx : ARX
        The structure.
    ts : float
        Sample time in seconds.
    method, predictor, parametrization : str
        How it was estimated (``predictor`` is the one the cost uses).
    initial : {"rest", "measured"}
        Initial condition of the cost's simulation (see :class:`PaperCost`).
        :meth:`from_dict` reads a dict without it (saved before the option
        existed) as ``"measured"``, the rule that produced it.
    gain : float
        The cost's gain ``w``.
    penalty : float
        The cost's stability penalty.
    cost : float
        The paper's cost, eq. (2)-(3), of ``theta`` on the estimation data.
    result : EstimatorResult or None
        What the estimator returned
        (:class:`~spiralid.sysid.estimation.core.estimators.EstimatorResult`, an
        ``OptimizeResult`` whose ``x`` is ``theta``; ``status`` says whether
        it stopped at an evaluation cap, ``start`` which start ``"oe"`` kept);
        ``None`` after :meth:`from_dict`.
    refine_result : EstimatorResult or None
        The local polish's result when ``refine=True`` (``result.refine``).
    history : ndarray or None
        Best cost after each iteration of the spiral search.
    timings : dict
        Wall times in seconds: ``"search"``, ``"refine"``, ``"total"``.
    bounds : ndarray or None, shape (p, 2)
        The search box of a spiral method (in the searched parameters).
    input_name, output_name, input_unit, output_unit : str
        The record's signal names and units, for tables and figure labels.
    u_offset, y_offset : float
        Offsets removed from the record before estimation; ``spiralid
        validate`` removes the same from new data.
    fraction : float or None
        The share of the record that estimated the model (the CLI's
        ``--fraction``), when known.
    integrator : int
        The number of known integrators (poles at ``z = 1``) factored out
        before estimation (``identify(integrator=True)`` is 1, ``2`` a
        double integrator such as torque to angle): the model is marginally
        stable by design, not unstable. 0 (or False): none.
    covariance : ndarray or None, shape (p', p')
        The covariance of the estimated parameters, ``s^2 (J^T J)^-1`` at the
        optimum
        (:func:`~spiralid.sysid.estimation.core.uncertainty.parameter_covariance`),
        over ``[free_denominator, b]`` (``p' = p - integrator``: a known
        integrator's pole is not estimated); None when not computed.
    covariance_factor : ndarray or None, shape (k, p')
        A square-root factor ``R`` of :attr:`covariance` (``C = R^T R``),
        which the mode intervals use for precision; not saved in model.json
        (a model read back uses the covariance itself).
    noise_variance : float
        ``s^2``, the variance of the error the estimator minimised (NaN when
        not computed).
    cancellations : tuple of dict
        The near-cancelling pole-zero pairs removed after the estimation
        (``identify(cancel=True)``,
        :mod:`~spiralid.sysid.estimation.spiral.cancellation`): each with the
        ``pole`` and ``zero`` (``[re, im]``, the upper one of a complex
        pair), its ``order`` (1 real, 2 a complex pair), their
        ``distance``, the ``tolerance`` and the ``cost_increase`` (a share
        of the cost). The removed coefficients are zeros at the end of
        ``a`` and ``b``; :attr:`effective_order` is what is left. A pole
        removed because the modes table flagged it (:attr:`diagnosis`) has
        a ``reason`` too, and its ``tolerance`` is the likelihood-ratio
        test's.
    selection : dict or None
        How the recommended method chose among its distinct minima on the
        held-back end of the estimation record
        (:mod:`~spiralid.sysid.estimation.spiral.heldback`): the ``holdback``
        share, ``n_held`` samples, the ``candidates`` (``start``,
        ``held_back_rms``, whole-record ``cost``), the ``chosen`` one, the
        ``lowest_cost`` one and a ``note`` in words; None when the method
        chose by the cost alone.
    margin : dict or None
        What the held-back end said of the default stability margin where it
        bound a pole (:mod:`~spiralid.sysid.estimation.spiral.margin_choice`): the
        margin's ``time_constant`` and the bound pole's (``slowest``, in
        seconds), the released minimum's ``released_cost`` as a share of
        the margined one's, the ``holdback`` share and ``n_held`` samples, the
        ``held_back_rms`` of the model with the margin and without
        (``"margin"``, ``"free"``), whether it was ``lifted`` and a ``note``
        in words; None when the margin did not bind, was given explicitly
        or was off.
    diagnosis : dict or None
        What the recommended method did with the poles its modes table
        flags (an interval that reaches ``|z| = 1``, a cancelling zero;
        :mod:`~spiralid.sysid.estimation.spiral.spurious`): the poles ``removed``
        (also in :attr:`cancellations`, with a ``reason``) and ``kept``
        (each with the ``cost_increase`` its removal took and the test's
        ``tolerance``), the record's ``n_samples`` and the error's
        ``n_effective`` samples the test used, and a ``note`` in words;
        None when no pole was flagged or with ``cancel=False``.
    """

    theta: np.ndarray
    arx: ARX
    ts: float
    _: KW_ONLY
    parametrization: str = "coefficients"
    refine_result: Any = None
    bounds: np.ndarray | None = None
    # Known integrators (poles at z = 1) factored out of the denominator
    # before estimation (`identify(integrator=...)`): the model is then
    # marginally stable by design, not unstable.
    integrator: int = 0
    covariance: np.ndarray | None = None
    covariance_factor: np.ndarray | None = None
    noise_variance: float = float("nan")
    cancellations: tuple = ()
    selection: dict | None = None
    margin: dict | None = None
    diagnosis: dict | None = None

    def __post_init__(self) -> None:
        self._check_provenance()
        self.theta = np.asarray(self.theta, dtype=float).copy()
        if self.theta.shape != (self.arx.n_params,):
            raise ValueError(
                f"`theta` must have shape ({self.arx.n_params},) for {self.arx}; "
                f"got {self.theta.shape}"
            )
        if not np.all(np.isfinite(self.theta)):
            bad = int(np.flatnonzero(~np.isfinite(self.theta))[0])
            raise ValueError(
                f"`theta` must be finite; got {self.theta[bad]!r} at index {bad}"
            )
        self.integrator = integrator_count(self.integrator, self.arx.na)
        if self.integrator:
            a = self.theta[: self.arx.na]
            back = with_integrator(
                deflate_integrator(a, self.integrator), self.integrator
            )
            if not np.allclose(
                back, a, rtol=0.0, atol=1e-9 * np.abs(np.r_[1.0, a]).sum()
            ):
                raise ValueError(
                    f"`integrator` = {self.integrator} needs a denominator with "
                    f"that many poles at z = 1; got A(1) = {1.0 + a.sum():.3g}"
                )
        if self.covariance is not None:
            self.covariance = np.asarray(self.covariance, dtype=float)
            free = self.arx.n_params - self.integrator
            if self.covariance.shape != (free, free):
                raise ValueError(
                    f"`covariance` must have shape ({free}, {free}) for {self.arx}"
                    f"{' with an integrator' if self.integrator else ''}; got "
                    f"{self.covariance.shape}"
                )
        self.cancellations = tuple(self.cancellations)
        na_eff, nb_eff = self.effective_order
        removed = np.r_[
            self.theta[na_eff : self.arx.na], self.theta[self.arx.na + nb_eff :]
        ]
        if na_eff < 0 or nb_eff < 1 or np.any(removed != 0.0):
            raise ValueError(
                "`cancellations` must leave na >= 0, nb >= 1 and zeros where "
                f"the pairs were removed; got effective order ({na_eff}, "
                f"{nb_eff}) of {self.arx}"
            )
        biggest = float(np.max(np.abs(self.theta), initial=0.0))
        if biggest > _MAX_COEFFICIENT:
            # Two such coefficients multiplied pass float64's range (1.8e308):
            # poles, zeros and every simulation would overflow.
            raise ValueError(
                f"`theta` overflows: a coefficient of magnitude {biggest:.3g} is "
                f"beyond {_MAX_COEFFICIENT:g}"
            )

    # -- model behaviour ---------------------------------------------------------

    @property
    def structure(self) -> ARX:
        """The structure (:attr:`arx`), under the name every fitted model
        answers to."""
        return self.arx

    @property
    def params(self) -> np.ndarray:
        """The parameters (:attr:`theta`), under the name every fitted
        model answers to."""
        return self.theta

    @property
    def linear_part(self) -> IdentifiedModel:
        """The linear model inside this one: the model itself."""
        return self

    def simulate(self, u) -> np.ndarray:
        """Free-run output from zero initial conditions (``IOData`` gives its u)."""
        return self.arx.simulate(self.theta, u)

    def predict(self, data: IOData) -> np.ndarray:
        """One-step-ahead prediction on `data`."""
        return self.arx.predict(self.theta, data)

    @property
    def effective_order(self) -> tuple[int, int]:
        """``(na, nb)`` left after the removed pole-zero pairs
        (:attr:`cancellations`); the structure's own when none was."""
        k = sum(int(c["order"]) for c in self.cancellations)
        return self.arx.na - k, self.arx.nb - k

    def _effective(self) -> tuple[ARX, np.ndarray]:
        """The structure and theta of :attr:`effective_order` (the same
        transfer function, without the removed coefficients' zeros)."""
        if not self.cancellations:
            return self.arx, self.theta
        na, nb = self.effective_order
        arx = ARX(na, nb, self.arx.nk)
        return arx, np.r_[self.theta[:na], self.theta[self.arx.na : self.arx.na + nb]]

    @property
    def polynomials(self) -> tuple[np.ndarray, np.ndarray]:
        """``(num, den)`` in ``z^-1``, equal lengths (see ``ARX.polynomials``),
        of the :attr:`effective_order`."""
        arx, theta = self._effective()
        return arx.polynomials(theta)

    @property
    def poles(self) -> np.ndarray:
        """Poles in z (of the :attr:`effective_order`: none for a removed
        pair)."""
        arx, theta = self._effective()
        return arx.poles(theta)

    @property
    def zeros(self) -> np.ndarray:
        """Finite zeros in z (of the :attr:`effective_order`)."""
        arx, theta = self._effective()
        return arx.zeros(theta)

    @property
    def reduction(self) -> str | None:
        """What the pole-zero cancellation removed, in a sentence, or None."""
        if not self.cancellations:
            return None
        na, nb = self.effective_order
        near = [c for c in self.cancellations if "reason" not in c]
        flagged = [c for c in self.cancellations if "reason" in c]
        parts = []
        if near:
            where = ", ".join(_root_text(c["pole"]) for c in near)
            dist = max(float(c["distance"]) for c in near)
            tol = float(near[0]["tolerance"])
            # Each removal's rise is of the cost before any: the last is the
            # total.
            rise = float(near[-1]["cost_increase"])
            n = len(near)
            parts.append(
                f"{n} near-cancelling pole-zero pair{'s' if n > 1 else ''} "
                f"removed after the estimation (pole at z = {where}; |p - z| <= "
                f"{dist:.2g}, below the record's resolution 2 pi / N = {tol:.2g}; "
                f"estimation cost {100 * rise:+.2g} %)"
            )
        if flagged:
            where = ", ".join(_root_text(c["pole"]) for c in flagged)
            rise = float(flagged[-1]["cost_increase"])
            tol = float(flagged[-1]["tolerance"])
            n = len(flagged)
            parts.append(
                f"{n} pole{'s' if n > 1 else ''} the modes table flags removed "
                f"(z = {where}; {flagged[0]['reason']}; estimation cost "
                f"{100 * rise:+.2g} % of the estimate after the cancellation, "
                f"within the likelihood-ratio test's {100 * tol:.2g} %)"
            )
        return (
            f"{' and '.join(parts)}: effective order na = {na}, nb = {nb} of {self.arx}"
        )

    @property
    def free_denominator(self) -> np.ndarray:
        """The denominator's coefficients ``a_1..`` without the known
        integrator: the poles the estimation chose (all of them when
        ``integrator`` is False)."""
        return deflate_integrator(self.theta[: self.arx.na], self.integrator)

    @property
    def is_stable(self) -> bool:
        """Every pole strictly inside the unit circle: spiralid's one
        stability verdict (see :mod:`spiralid.sysid.models.polynomials`).
        With a known integrator, the verdict is on the other poles (the
        model is marginally stable by design)."""
        return bool(is_stable_polynomial(self.free_denominator))

    @property
    def max_pole_radius(self) -> float:
        """Largest ``|pole|``, on the verdict's side of the unit circle
        (:func:`~spiralid.sysid.models.polynomials.max_pole_radius`), over
        the poles the estimation chose (the integrator's is 1)."""
        return float(max_pole_radius(self.free_denominator))

    @property
    def standard_errors(self) -> np.ndarray | None:
        """The estimated parameters' standard errors (``sqrt`` of
        :attr:`covariance`'s diagonal, in its order), or None."""
        if self.covariance is None:
            return None
        return np.sqrt(np.diag(self.covariance))

    @property
    def modes(self) -> ModeTable:
        """The complex pole pairs as modes: natural frequency (Hz), damping
        ratio, 95 % intervals from :attr:`covariance` (delta method), each
        mode's share of the output, and flags for an interval that reaches
        ``|z| = 1``, a near pole-zero cancellation and a probably spurious
        mode (see :class:`~spiralid.sysid.models.modes.ModeTable`). A known
        integrator is not a mode."""
        a = self.free_denominator
        cov = None if self.covariance is None else self.covariance[: a.size, : a.size]
        root = self.covariance_factor
        root = None if root is None else root[:, : a.size]
        b = self.polynomials[0] if not self.integrator else self._free_numerator()
        return mode_table(a, b, self.ts, covariance=cov, factor=root)

    def _free_numerator(self) -> np.ndarray:
        # With a known integrator the estimated model is B / A' on the
        # summed input; its numerator is B itself.
        return np.r_[np.zeros(self.arx.nk), self.theta[self.arx.na :]]

    def tf_string(self, digits: int = 4) -> str:
        """Transfer function in z as eq. (9)-(10) print it (of the
        :attr:`effective_order`)."""
        arx, theta = self._effective()
        return arx.tf_string(theta, digits=digits)

    def to_dlti(self) -> signal.dlti:
        """The model as a ``scipy.signal.dlti`` transfer function with ``dt = ts``."""
        num, den = self.polynomials
        # Leading zeros (nk > 0) are exact in positive powers of z; dropping
        # them avoids SciPy's "badly conditioned" warning.
        nz = np.flatnonzero(num)
        num = num[nz[0] :] if nz.size else num[-1:]
        return signal.dlti(num, den, dt=self.ts)

    def to_control(self):
        """The model as a python-control ``TransferFunction`` in z, ``dt = ts``.

        Needs python-control, an optional dependency:
        ``pip install "spiralid[control]"``.
        """
        control = python_control()
        dlti = self.to_dlti()
        return control.tf(dlti.num, dlti.den, self.ts)

    # -- serialisation -----------------------------------------------------------

    def to_dict(self, *, timings: bool = True) -> dict:
        """A JSON-safe summary (the optimiser result is reduced to its history).

        ``timings=False`` leaves out the wall times, the only part that
        differs between two runs with the same seed (``spiralid identify``
        writes them to ``timings.json`` beside ``model.json``)."""
        out = {
            "theta": [float(v) for v in self.theta],
            "na": self.arx.na,
            "nb": self.arx.nb,
            "nk": self.arx.nk,
            "ts": float(self.ts),
            "parametrization": self.parametrization,
            **self._provenance_dict(),
            "bounds": None if self.bounds is None else np.asarray(self.bounds).tolist(),
            "integrator": self.integrator,
            "covariance": None
            if self.covariance is None
            else np.where(np.isfinite(self.covariance), self.covariance, None).tolist(),
            "noise_variance": _finite_or_none(self.noise_variance),
            "cancellations": [dict(c) for c in self.cancellations],
            "selection": self.selection,
            "margin": self.margin,
            "diagnosis": self.diagnosis,
            "modes": self.modes.to_dict(),
        }
        if out["result"] is not None and self.refine_result is not None:
            out["result"]["refine"] = result_summary(self.refine_result)
        if not timings:
            del out["timings"]
        return out

    @classmethod
    def from_dict(cls, d: dict) -> IdentifiedModel:
        """Rebuild from :meth:`to_dict` output (``result`` is not restored);
        a field that is missing or out of range (``ts <= 0``, an unknown
        method, a ``fraction`` outside (0, 1)...) raises a ValueError that
        names it."""
        if not isinstance(d, dict):
            raise ValueError(f"a model must be a JSON object; got {type(d).__name__}")
        kind = d.get("model", "arx")
        if kind != "arx":
            # to_dict writes none; NARXModel.to_dict writes 'narx'.
            raise ValueError(
                "field 'model' must be absent or 'arx' for an ARX model ('narx' "
                f"for NARXModel.from_dict); got {kind!r}"
            )
        try:
            for name in ("na", "nb", "nk"):
                # Named as the file names them, not as the command's options.
                if isinstance(d[name], bool) or not isinstance(d[name], int):
                    raise ValueError(
                        f"field {name!r} must be an integer; got {d[name]!r}"
                    )
            arx = ARX(d["na"], d["nb"], d["nk"])
            return cls(
                theta=np.asarray(d["theta"], dtype=float),
                arx=arx,
                ts=_fields.number(d, "ts", "a number > 0", _fields.positive),
                parametrization=d.get("parametrization", "coefficients"),
                # Dicts saved before `initial` existed came from the
                # measured-past rule, which was then the only one.
                **cls._provenance_fields(d, _arx_methods(), initial="measured"),
                bounds=None if d.get("bounds") is None else np.asarray(d["bounds"]),
                integrator=_integrator_field(d),
                covariance=_covariance_field(d),
                noise_variance=_fields.number(
                    d,
                    "noise_variance",
                    "a number >= 0 or null",
                    _fields.nonneg,
                    math.nan,
                )
                if d.get("noise_variance") is not None
                else math.nan,
                cancellations=_cancellations_field(d),
                selection=_note_field(d, "selection"),
                margin=_note_field(d, "margin"),
                diagnosis=_note_field(d, "diagnosis"),
            )
        except KeyError as exc:
            raise ValueError(f"the field {exc.args[0]!r} is missing") from None

    def __repr__(self) -> str:
        return (
            f"IdentifiedModel({self.arx}, method={self.method!r}, "
            f"predictor={self.predictor!r}, initial={self.initial!r}, "
            f"cost={self.cost:.6g}, "
            f"stable={self.is_stable})"
        )


def _finite_or_none(value: float) -> float | None:
    return float(value) if np.isfinite(value) else None


def _root_text(root) -> str:
    re, im = (float(v) for v in root)
    return f"{re:.4g}" if im == 0.0 else f"{re:.4g} +- {abs(im):.4g}j"


def _integrator_field(d: dict) -> int:
    """The file's ``integrator``: a count (``true`` is 1, as older files
    wrote it)."""
    value = d.get("integrator", 0)
    if not isinstance(value, bool | int):
        raise ValueError(
            f"field 'integrator' must be a count >= 0 or true/false; got {value!r}"
        )
    return int(value)


def _note_field(d: dict, name: str) -> dict | None:
    """The file's ``selection`` or ``margin``: an object with a ``note``, or
    null (absent in files written before it)."""
    value = d.get(name)
    if value is not None and not (isinstance(value, dict) and "note" in value):
        raise ValueError(
            f"field {name!r} must be an object with a 'note' or null; got {value!r}"
        )
    return value


def _cancellations_field(d: dict) -> tuple:
    """The file's ``cancellations``: a list of objects with a ``pole`` and a
    ``zero`` ([re, im]), an ``order`` (1 or 2) and three numbers."""
    raw = d.get("cancellations") or []
    bad = ValueError(
        "field 'cancellations' must be a list of objects with 'pole' and 'zero' "
        "([re, im]), 'order' (1 or 2), 'distance', 'tolerance' and "
        "'cost_increase'"
    )
    if not isinstance(raw, list):
        raise bad
    out = []
    for c in raw:
        try:
            entry = {
                "pole": [float(v) for v in c["pole"]],
                "zero": [float(v) for v in c["zero"]],
                "order": c["order"],
                "distance": float(c["distance"]),
                "tolerance": float(c["tolerance"]),
                "cost_increase": float(c["cost_increase"]),
            }
            if "reason" in c:
                # A pole removed on the modes table's flags (spurious.py).
                entry["reason"] = str(c["reason"])
        except (KeyError, TypeError, ValueError):
            raise bad from None
        if (
            len(entry["pole"]) != 2
            or len(entry["zero"]) != 2
            or entry["order"] not in (1, 2)
            or isinstance(entry["order"], bool)
        ):
            raise bad
        out.append(entry)
    return tuple(out)


def _covariance_field(d: dict) -> np.ndarray | None:
    """The file's ``covariance``: a square array, ``null`` for an infinite
    variance (JSON has no infinity)."""
    raw = d.get("covariance")
    if raw is None:
        return None
    try:
        cov = np.array(
            [[np.inf if v is None else v for v in row] for row in raw], dtype=float
        )
    except (TypeError, ValueError):
        raise ValueError(
            "field 'covariance' must be a square array of numbers"
        ) from None
    if cov.ndim != 2 or cov.shape[0] != cov.shape[1] or np.isnan(cov).any():
        raise ValueError("field 'covariance' must be a square array of numbers")
    return cov


def _arx_methods() -> tuple[str, ...]:
    """The methods an ARX model file may name: identify()'s, and the
    Pareto search's (``"pareto-ebsda"``...)."""
    from spiralid.choices import METHOD_NAMES as METHODS
    from spiralid.choices import PARETO_METHOD_NAMES as PARETO_METHODS

    return (*METHODS, *(f"pareto-{name}" for name in PARETO_METHODS))
