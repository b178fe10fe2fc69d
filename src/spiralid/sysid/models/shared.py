"""Several outputs, one denominator: :class:`SharedDenominatorModel`.

A flexible structure's sensors (hub angle, hub velocity, end-point
acceleration, tip deflection) are driven by one torque and share the
structure's modes: their transfer functions have one denominator ``A(q)``
and a numerator each,

    y_i(t) = B_i(q) / A(q) u(t),   i = 1..p,

a single-input multi-output (SIMO) output-error model. The modes are the
complex pole pairs of ``A``, with intervals from the covariance of ``a``
(:func:`~spiralid.sysid.models.modes.mode_table`), and each mode's share in
each output from that output's residues: a sensor near a node of a mode
barely sees it, the others do. Several inputs (shakers) make it
``y_i = sum_j B_ij(q) / A(q) u_j``, one numerator per pair over the same
poles (run, predicted and realised in ``_shared_inputs.py``).
"""

from __future__ import annotations

from dataclasses import KW_ONLY, dataclass, field

import numpy as np
from scipy import signal

from spiralid._checks import named_index

from . import _fields
from . import _shared_file as _file
from . import _shared_inputs as _several_inputs
from ._shared_inputs import one_per, simo_state_space
from .arx import ARX
from .fitted import Provenance
from .identified import IdentifiedModel, python_control
from .modes import ModeTable, interval_format, mode_table
from .polynomials import is_stable_polynomial, max_pole_radius, with_integrator
from .shapes import ModeShapes, pair_shapes

__all__ = ["MOST_INTEGRATORS", "SharedDenominatorModel", "SharedModes"]


@dataclass(frozen=True)
class SharedModes:
    """The shared denominator's modes, with each mode's share per output.

    Attributes
    ----------
    table : ModeTable
        Frequencies (Hz), damping ratios and their 95 % intervals, from the
        covariance of the shared denominator; its ``share`` and flags are
        those of the output where the mode is strongest.
    share : ndarray, shape (m, p)
        Each mode's resonant peak as a share of each output's (a column per
        output, :attr:`ModeTable.share` of ``B_i / A``: after the output's
        known integrators are taken out, whose poles at ``z = 1`` would
        hold an infinite peak).
    output_names : tuple of str
    """

    table: ModeTable
    share: np.ndarray
    output_names: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.table)

    def to_dict(self) -> dict:
        out = self.table.to_dict()
        out["share_by_output"] = {
            name: [_fields.plain(v) for v in self.share[:, k]]
            for k, name in enumerate(self.output_names)
        }
        return out

    def __str__(self) -> str:
        t = self.table
        if not len(t):
            return "no modes (no complex pole pair)"
        lo_f, hi_f = t.frequency_interval.T
        lo_z, hi_z = t.damping_interval.T
        widths = [max(14, len(n)) for n in self.output_names]
        head = (
            f"{'mode':>4}  {'frequency (Hz) [95 %]':>30}  {'damping [95 %]':>30}  "
            + "  ".join(
                f"{n:>{w}}" for n, w in zip(self.output_names, widths, strict=True)
            )
        )
        lines = [head]
        for i in range(len(t)):
            ff = interval_format((lo_f[i], hi_f[i]))
            fd = interval_format((lo_z[i], hi_z[i]), "f")
            freq = f"{t.frequency[i]:{ff}} [{lo_f[i]:{ff}}, {hi_f[i]:{ff}}]"
            damp = f"{t.damping[i]:{fd}} [{lo_z[i]:{fd}}, {hi_z[i]:{fd}}]"
            shares = "  ".join(
                f"{100 * s:{w - 1}.1f}%"
                for s, w in zip(self.share[i], widths, strict=True)
            )
            lines.append(f"{i + 1:>4}  {freq:>30}  {damp:>30}  {shares}")
        return "\n".join(lines)


# Known integrators per output, outside the shared denominator: a hub
# angle's double integrator at most (a torque drives an acceleration).
MOST_INTEGRATORS = 2


@dataclass
class SharedDenominatorModel(Provenance):
    """A model of one or several outputs (and inputs) with one denominator.

    Its provenance (method, cost, result, timings, input name and offset,
    fraction...) is the record-wide :class:`~.fitted.Provenance` every
    fitted model holds, written to and read from its file alike; the
    output's name, unit and offset of a one-output
    :class:`~.fitted.FittedModel` are here one per output.

    Parameters
    ----------
    a : ndarray, shape (na,)
        The shared denominator ``A = 1 + a_1 q^-1 + ...``.
    b : ndarray, shape (p, nb)
        One numerator per output (coefficients of ``q^-nk .. q^-(nk+nb-1)``).
    arx : ARX
        The structure each output has (``na``, ``nb``, ``nk``).
    ts : float
        Sample time in seconds.
    output_names, output_units : tuple of str
        One per output.
    input_name, input_unit : str
    u_offset : float
    y_offsets : tuple of float
        Offsets removed from the record (as :class:`IdentifiedModel`'s).
    method : str
        The estimator.
    cost : float
        The weighted joint cost the estimator minimised (percent RMS error,
        see :class:`~spiralid.sysid.estimation.shared.denominator.SharedProjectedCost`).
    weights : ndarray, shape (p,)
        The outputs' weights in that cost (``1 / sigma_i^2``).
    costs : ndarray, shape (p,)
        Each output's own paper cost, eq. (2), at the estimate.
    covariance : ndarray, shape (na, na), or None
        The covariance of ``a`` (variable projection: the numerators
        projected out), for the modes' intervals.
    covariance_factor : ndarray or None, shape (na, na)
        A square-root factor ``R`` of :attr:`covariance` (``C = R^T R``),
        which the mode intervals use for precision; not saved in model.json
        (a model read back uses the covariance itself).
    integrators : tuple of int
        Each output's known integrators, poles at ``z = 1`` outside the
        shared ``A``: output ``i`` is ``B_i / (A (1 - z^-1)^k_i)``.
    result : dict
        What the estimator reports (budget, messages); the model file keeps
        its scalars.
    shape_factor : ndarray or None, shape (k, na + p nb)
        A square-root factor of the covariance of every parameter
        (:attr:`params`), for the mode shapes' intervals
        (:attr:`shapes`), saved in model.json so that a model read back
        has the same shapes' intervals.
    predictor, initial : str
        ``"simulation"`` and ``"rest"``: the joint cost is the outputs'
        free-run error from rest.
    gain : float
        NaN: the joint cost weights each output by its noise, not by one
        gain of eq. (2).
    penalty : float
        0: an unstable estimate has no cost (NaN), not a penalised one.
    history : ndarray or None
        Best cost after each iteration of a search (None: not kept).
    timings : dict
        Wall times in seconds (``"total"``: the estimation's), written to
        the file unless ``to_dict(timings=False)``.
    fraction : float or None
        The share of the record that estimated the model, when known.
    input_names, input_units : tuple of str
        With several inputs, one name and unit per input (``b`` then has
        ``m nb`` coefficients per output, input by input: output ``i`` is
        ``sum_j B_ij / A u_j``); empty for the one input of `input_name`.
    u_offsets : tuple of float
        With several inputs, the offset removed from each.
    """

    a: np.ndarray
    b: np.ndarray
    arx: ARX
    ts: float
    output_names: tuple[str, ...]
    output_units: tuple[str, ...] = ()
    y_offsets: tuple[float, ...] = ()
    weights: np.ndarray | None = None
    costs: np.ndarray | None = None
    covariance: np.ndarray | None = None
    covariance_factor: np.ndarray | None = None
    integrators: tuple[int, ...] = ()
    _: KW_ONLY
    # The provenance's fields whose defaults differ for several outputs.
    method: str = "spiral"
    penalty: float = 0.0
    result: dict = field(default_factory=dict)
    # Several inputs: one name, unit and offset each (empty: the one input
    # of the provenance's input_name, input_unit and u_offset).
    input_names: tuple[str, ...] = ()
    input_units: tuple[str, ...] = ()
    u_offsets: tuple[float, ...] = ()
    shape_factor: np.ndarray | None = None

    def __post_init__(self) -> None:
        self._check_provenance()
        _several_inputs.check_inputs(self)
        self.a = np.asarray(self.a, dtype=float).ravel()
        self.b = np.atleast_2d(np.asarray(self.b, dtype=float))
        p = self.b.shape[0]
        width = self.n_inputs * self.arx.nb
        if self.a.shape != (self.arx.na,) or self.b.shape[1] != width:
            raise ValueError(
                f"`a` and `b` must have shapes ({self.arx.na},) and (p, "
                f"{width}) for {self.arx} and {self.n_inputs} input(s); got "
                f"{self.a.shape} and {self.b.shape}"
            )
        if not (np.all(np.isfinite(self.a)) and np.all(np.isfinite(self.b))):
            raise ValueError("`a` and `b` must be finite")
        self.output_names = tuple(self.output_names)
        if len(self.output_names) != p or len(set(self.output_names)) != p:
            raise ValueError(
                f"`output_names` must name each of the {p} outputs once; got "
                f"{self.output_names}"
            )
        self.output_units = one_per(self.output_units, p, "output_units", "")
        self.y_offsets = one_per(self.y_offsets, p, "y_offsets", 0.0)
        if not all(np.isfinite(self.y_offsets)):
            raise ValueError(f"`y_offsets` must be finite; got {self.y_offsets}")
        self.integrators = one_per(self.integrators, p, "integrators", 0)
        if not all(0 <= k <= MOST_INTEGRATORS for k in self.integrators):
            raise ValueError(
                f"`integrators` must be counts in [0, {MOST_INTEGRATORS}], one per "
                f"output; got {self.integrators}"
            )
        for name, value in (("costs", self.costs), ("weights", self.weights)):
            if value is not None and np.shape(value) != (p,):
                raise ValueError(
                    f"`{name}` must hold one number per output ({p}); got shape "
                    f"{np.shape(value)}"
                )
        if self.covariance is not None:
            self.covariance = np.asarray(self.covariance, dtype=float)
            na = self.arx.na
            if self.covariance.shape != (na, na) or np.isnan(self.covariance).any():
                raise ValueError(
                    f"`covariance` must be the ({na}, {na}) covariance of `a`; got "
                    f"shape {self.covariance.shape}"
                )

    @property
    def n_outputs(self) -> int:
        return int(self.b.shape[0])

    @property
    def n_inputs(self) -> int:
        """Number of inputs ``m`` (1: the single-input model)."""
        return len(self.input_names)

    def numerator(self, which: int | str, input: int | str = 0) -> np.ndarray:
        """``B_ij``'s coefficients (nb,): output `which`'s numerator from
        input `input` (names or 0-based indices)."""
        i = named_index(which, "which", self.output_names)
        j = named_index(input, "input", self.input_names)
        nb = self.arx.nb
        return self.b[i, j * nb : (j + 1) * nb]

    @property
    def structure(self) -> ARX:
        """The structure every output has (:attr:`arx`), under the name
        every fitted model answers to."""
        return self.arx

    @property
    def params(self) -> np.ndarray:
        """Every estimated parameter, ``[a, b_1, ..., b_p]`` (the shared
        denominator, then each output's numerator; with several inputs
        ``b_i = [b_i1, .., b_im]``)."""
        return np.r_[self.a, self.b.ravel()]

    @property
    def theta(self) -> np.ndarray:
        """The parameters (:attr:`params`), as an ARX fit's ``theta``."""
        return self.params

    @property
    def is_linear(self) -> bool:
        """True: the modes and stability come from the shared poles."""
        return True

    @property
    def linear_part(self) -> SharedDenominatorModel:
        """The linear model inside this one: the model itself."""
        return self

    def output_theta(self, i: int, j: int = 0) -> np.ndarray:
        """Output `i`'s ARX theta ``[a, b_ij]`` from input `j` with its
        known integrators in the denominator (the structure of
        :meth:`output_arx`)."""
        nb = self.arx.nb
        b = self.b[i] if self.n_inputs == 1 else self.b[i, j * nb : (j + 1) * nb]
        return np.r_[with_integrator(self.a, self.integrators[i]), b]

    def output_arx(self, i: int) -> ARX:
        """Output `i`'s structure: the shared poles and its integrators."""
        return ARX(self.arx.na + self.integrators[i], self.arx.nb, self.arx.nk)

    def simulate(self, u) -> np.ndarray:
        """Free run of every output from rest, shape (N, p); `u` of shape
        (N, m) with several inputs (the sum of each input's response)."""
        u = np.asarray(getattr(u, "u", u), dtype=float)
        if self.n_inputs > 1:
            return _several_inputs.simulate(self, u)
        return np.column_stack(
            [
                self.output_arx(i).simulate(self.output_theta(i), u)
                for i in range(self.n_outputs)
            ]
        )

    def predict(self, data) -> np.ndarray:
        """One-step-ahead prediction of every output on `data` (a record
        holding the model's outputs by name), shape (N, p)."""
        if self.n_inputs > 1:
            return _several_inputs.predict(self, data)
        return np.column_stack(
            [
                self.output_model(name).predict(data.output(name))
                for name in self.output_names
            ]
        )

    def output_model(
        self, which: int | str, input: int | str | None = None
    ) -> IdentifiedModel:
        """One output's transfer function ``B_i / A`` as an
        :class:`IdentifiedModel`, which :func:`~spiralid.sysid.validate`
        validates on that output (its covariance is not carried: the
        intervals belong to the shared modes). With several inputs `input`
        names one: ``B_ij / A``, one pair's transfer function (the output
        is the sum over the inputs; a one-line ValueError without it)."""
        i = named_index(which, "which", self.output_names)
        if self.n_inputs > 1 and input is None:
            raise ValueError(
                f"`input` must name one of the model's inputs {self.input_names}: "
                "each output of a model of several inputs is their sum"
            )
        j = 0 if input is None else named_index(input, "input", self.input_names)
        return IdentifiedModel(
            self.output_theta(i, j),
            arx=self.output_arx(i),
            integrator=self.integrators[i],
            ts=self.ts,
            method=self.method,
            cost=float(self.costs[i]) if self.costs is not None else float("nan"),
            input_name=self.input_names[j],
            output_name=self.output_names[i],
            input_unit=self.input_units[j],
            output_unit=self.output_units[i],
            u_offset=self.u_offsets[j],
            y_offset=self.y_offsets[i],
        )

    @property
    def poles(self) -> np.ndarray:
        return np.roots(np.r_[1.0, self.a]) if self.arx.na else np.zeros(0, complex)

    @property
    def is_stable(self) -> bool:
        return bool(is_stable_polynomial(self.a))

    @property
    def max_pole_radius(self) -> float:
        return float(max_pole_radius(self.a))

    @property
    def modes(self) -> SharedModes:
        """The shared modes with 95 % intervals and each one's share per
        output."""
        if self.n_inputs > 1:
            return _several_inputs.modes(self, SharedModes)
        b_full = [np.r_[np.zeros(self.arx.nk), bi] for bi in self.b]
        tables = [
            mode_table(
                self.a,
                bi,
                self.ts,
                covariance=self.covariance,
                factor=self.covariance_factor,
            )
            for bi in b_full
        ]
        share = (
            np.column_stack([t.share for t in tables]) if tables else np.zeros((0, 0))
        )
        strongest = int(np.argmax(np.nansum(share, axis=0))) if share.size else 0
        return SharedModes(tables[strongest], share, self.output_names)

    @property
    def shapes(self) -> ModeShapes:
        """The shapes of :attr:`modes` over the outputs, from each output's
        residues, with 95 % intervals (:func:`~.shapes.mode_shapes`); a
        model of several inputs has them per input (:meth:`input_shapes`)."""
        if self.n_inputs > 1:
            raise ValueError(
                f"this model has {self.n_inputs} inputs "
                f"({', '.join(self.input_names)}): take the shapes one input "
                "excites with model.input_shapes(input)"
            )
        return self.input_shapes(0)

    def input_shapes(self, input: int | str = 0) -> ModeShapes:
        """The shapes of :attr:`modes` over the outputs as the input `input`
        (a name or 0-based index) excites them (:func:`~.shapes.pair_shapes`).

        Parameters
        ----------
        input : int or str, default 0
            The input.

        Returns
        -------
        ModeShapes
        """
        j = named_index(input, "input", self.input_names)
        return pair_shapes(self, j)

    def tf_string(self, digits: int = 4) -> str:
        """Each output's transfer function in z (:meth:`output_model`'s),
        one line per output after its name (per input-output pair with
        several inputs)."""
        if self.n_inputs > 1:
            return "\n".join(
                f"{name} <- {u}: {self.output_model(name, u).tf_string(digits)}"
                for name in self.output_names
                for u in self.input_names
            )
        return "\n".join(
            f"{name}: {self.output_model(name).tf_string(digits)}"
            for name in self.output_names
        )

    def to_dlti(self) -> signal.dlti:
        """The model as a SIMO ``scipy.signal.dlti`` state-space system with
        ``dt = ts`` (the realisation of :meth:`to_control`)."""
        return signal.dlti(*self._state_space(), dt=self.ts)

    def summary(self) -> str:
        """The model in a few lines: structure, outputs, method, cost,
        stability and each output's transfer function."""
        return "\n".join(
            [
                f"SharedDenominatorModel of {', '.join(self.output_names)} from "
                f"{self.input_name!r}: {self.arx}",
                f"method {self.method}, joint cost {self.cost:.6g}, ts {self.ts:g} s",
                f"stable: {self.is_stable}",
                self.tf_string(),
            ]
        )

    def to_control(self):
        """The model as a python-control SIMO state-space system in z
        (``dt = ts``): one state for the shared denominator, a row of ``C``
        per output (``scipy.signal.tf2ss`` of the numerators over ``A``).
        Needs python-control (``pip install "spiralid[control]"``)."""
        control = python_control()
        return control.ss(*self._state_space(), self.ts)

    def _state_space(self):
        """``(A, B, C, D)`` of one state-space realisation of every output
        over the shared denominator (with several inputs, one block per
        input: not minimal, the poles repeated per input)."""
        if self.n_inputs > 1:
            return _several_inputs.state_space(self, simo_state_space)
        return simo_state_space(self.a, self.b, self.arx, self.integrators)

    def to_dict(self, *, timings: bool = True) -> dict:
        """A JSON-safe form (what ``model.json`` holds).

        Parameters
        ----------
        timings : bool, default True
            Include the wall times (``timings``), which differ between
            runs; False leaves them out, so that two runs with the same
            seed write the same file.
        """
        return _file.model_dict(self, timings)

    @classmethod
    def from_dict(cls, d: dict) -> SharedDenominatorModel:
        """The model :meth:`to_dict` wrote; a field that is missing, of the
        wrong type or out of range raises a ValueError that names it."""
        return cls(**_file.model_fields(d, cls._provenance_fields))

    def __repr__(self) -> str:
        return (
            f"SharedDenominatorModel({self.arx}, outputs={self.output_names}, "
            f"method={self.method!r}, cost={self.cost:.6g})"
        )
