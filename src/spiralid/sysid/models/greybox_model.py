"""The fitted grey box: :class:`GreyBoxModel` (nonlinear kind) and
:class:`LinearGreyBoxModel` (linear kind, with the linear members of
:class:`~spiralid.sysid.models.protocol.FittedModelProtocol`).

Its parameters carry 95 % intervals in their own units, from the polish's
Jacobian (see :mod:`spiralid.sysid.estimation.greybox`); a parameter the
record cannot determine has no interval and is named in ``undetermined``.

A model of several outputs simulates them all (shape (N, p)); its
``output_model(name)`` is the same model reading one of them, which
:func:`~spiralid.sysid.validate` validates output by output.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..data import IOData
from .greybox import GreyBox, _import
from .modes import ModeTable, mode_table
from .polynomials import is_stable_polynomial

__all__ = ["INTEGRATOR_TOLERANCE", "GreyBoxModel", "LinearGreyBoxModel"]

#: How close to ``z = 1`` a linear grey box's pole counts as an integrator
#: of its physics (:attr:`LinearGreyBoxModel.integrator`).
INTEGRATOR_TOLERANCE = 1e-6


# What the model keeps of its record (IOData's fields of the same names).
_RECORD = ("input_name", "input_unit", "output_unit", "u_offset", "y_offset")


def _inputs(u) -> np.ndarray:
    return np.asarray(u.u if isinstance(u, IOData) else u, dtype=float)


def _nth(value, k: int):
    """The `k`-th of a per-output tuple, or the one value for all."""
    return value[k] if isinstance(value, tuple) else value


def _plain(value):
    """A field as JSON holds it (a tuple as a list, a NumPy number as a
    float)."""
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return float(value) if isinstance(value, np.floating) else value


def _structure_from_dict(d: dict) -> GreyBox:
    """The structure a model file holds: a :class:`GreyBox`, or a class of
    its own named by import path (the rig's, which lives in ``fms``: the
    path keeps ``sysid`` from importing it)."""
    kind = _import(d["class"]) if "class" in d else GreyBox
    if not (isinstance(kind, type) and issubclass(kind, GreyBox)):
        raise ValueError(f"grey-box model file: {d['class']!r} is not a GreyBox")
    return kind.from_dict(d)


@dataclass
class GreyBoxModel:
    """A grey box fitted to a record.

    Attributes
    ----------
    structure : GreyBox
        The structure fitted (its parameters' initial values and bounds).
    values : ndarray
        Every parameter's value, fixed ones included, in the order of the
        structure's ``all_parameters`` (the functions', then the initial
        state's).
    ts : float
        The record's sample time.
    method : str
        The method that fitted it.
    cost : float
        The paper's eq. (2) on the simulation error.
    intervals : ndarray, shape (n, 2)
        Each parameter's 95 % interval in its unit; NaN for a fixed one and
        for one the record cannot determine.
    undetermined : list of str
        The parameters and combinations the record cannot determine, one
        sentence each.
    output_name : str or tuple of str
        The output's name (a tuple for several outputs, as ``IOData``'s).
    nfev : int
        Simulations the fit ran.
    input_name, input_unit : str
        The record's input name and unit, which the command line checks a
        validation record against.
    output_unit : str or tuple of str
        The output's unit (one per output for several).
    u_offset : float
        The offset removed from the record's input before the fit.
    y_offset : float or tuple of float
        The offsets removed from the record's outputs before the fit (its
        ``IOData``'s); the parameters describe the signals without them.
    output_fits : dict
        Each output's fit % on the estimation record (free run from the
        initial state), by name: what ``validate`` on that record reports.
    weights : ndarray, optional
        Each output's weight in the cost, one over its error variance at
        the fit (several outputs; 1 for a single output).
    column : int, optional
        For the one-output view ``output_model`` returns: which of the
        structure's outputs this model reads.
    """

    structure: GreyBox
    values: np.ndarray
    ts: float
    method: str
    cost: float = float("nan")
    intervals: np.ndarray | None = None
    undetermined: list = field(default_factory=list)
    output_name: str = "y"
    nfev: int = 0
    input_name: str = "u"
    input_unit: str = ""
    output_unit: str = ""
    u_offset: float = 0.0
    y_offset: float | tuple = 0.0
    output_fits: dict = field(default_factory=dict)
    weights: np.ndarray | None = None
    column: int | None = None

    def __post_init__(self) -> None:
        self.values = np.asarray(self.values, dtype=float)
        n = self.values.size
        if self.intervals is None:
            self.intervals = np.full((n, 2), np.nan)
        self.intervals = np.asarray(self.intervals, dtype=float).reshape(n, 2)
        for name in ("output_name", "output_unit", "y_offset"):
            value = getattr(self, name)
            if isinstance(value, list | tuple):  # as JSON gives it back
                setattr(self, name, tuple(value))
        if self.weights is not None:
            self.weights = np.asarray(self.weights, dtype=float).ravel()

    # -- the protocol -----------------------------------------------------------

    @property
    def params(self) -> np.ndarray:
        """The estimated (free) parameters' values."""
        return self.values[self.structure.free]

    @property
    def is_linear(self) -> bool:
        """False: a nonlinear grey box (see :class:`LinearGreyBoxModel`)."""
        return False

    @property
    def linear_part(self) -> LinearGreyBoxModel | None:
        """None: the nonlinear kind has no linear part declared (its
        linearisation is not built)."""
        return None

    @property
    def output_names(self) -> tuple[str, ...]:
        """The outputs' names, in the structure's order."""
        name = self.output_name
        return tuple(name) if isinstance(name, tuple) else (name,)

    def output_model(self, which: int | str) -> GreyBoxModel:
        """The model of the output `which` (index or name): the model
        itself for one output, else the same fit reading that output."""
        names = self.output_names
        if which in names:
            k = names.index(which)
        elif isinstance(which, int) and not isinstance(which, bool):
            k = which if 0 <= which < len(names) else -1
        else:
            k = -1
        if k < 0:
            raise ValueError(
                f"`which` must be an output's index or name {names}; got {which!r}"
            )
        if len(names) == 1:
            return self
        pick = dict(
            output_unit=_nth(self.output_unit, k), y_offset=_nth(self.y_offset, k)
        )
        return dataclasses.replace(
            self,
            output_name=names[k],
            output_fits={names[k]: self.output_fits.get(names[k], float("nan"))},
            weights=None if self.weights is None else self.weights[k : k + 1],
            column=k,
            **pick,
        )

    def simulate(self, u, y0=None) -> np.ndarray:
        """The free run from the structure's initial state over `u` (an
        ``IOData`` gives its ``u``), shape (N,) for one output, (N, p) for
        several. `y0` is accepted as every model's ``simulate`` takes it,
        and unused: a grey box reads no past outputs (``max_lag`` 0)."""
        y = self.structure.simulate(self.values, _inputs(u), self.ts)
        return y if self.column is None else y[:, self.column]

    def predict(self, data: IOData) -> np.ndarray:
        """The one-step prediction of an output-error model: its free run
        (a grey box has no noise model to correct it with the measured
        outputs)."""
        return self.simulate(data)

    # -- text and JSON --------------------------------------------------------------

    def parameter_rows(self) -> list[str]:
        """One line per parameter: value, unit, 95 % interval or why none."""
        rows = []
        for i, p in enumerate(self.structure.all_parameters):
            low, high = self.intervals[i]
            if not p.free:
                note = "fixed"
            elif np.isfinite(low):
                note = f"95 % [{low:.6g}, {high:.6g}]"
            else:
                note = "not determined by the record"
            rows.append(
                f"  {p.name} = {self.values[i]:.6g} {p.unit}".rstrip() + f"  {note}"
            )
        return rows

    def summary(self) -> str:
        """Structure, method, cost, each parameter with its unit and 95 %
        interval, and what the record cannot determine."""
        lines = [
            f"{self.structure}",
            f"method {self.method}, cost {self.cost:.6g} (eq. 2, simulation error), "
            f"ts = {self.ts:g} s",
            *self.parameter_rows(),
            *(f"  {note}" for note in self.undetermined),
            *self.output_rows(),
        ]
        return "\n".join(lines)

    def output_rows(self) -> list[str]:
        """One line per output of several: its fit % on the estimation
        record and its weight in the cost (none for one output)."""
        if len(self.output_names) == 1 or self.weights is None:
            return []
        return [
            f"  output {name}: fit {self.output_fits.get(name, np.nan):.2f} % on "
            f"the estimation record, noise sd {1 / np.sqrt(w):.4g}"
            for name, w in zip(self.output_names, self.weights, strict=True)
        ]

    def to_dict(self, *, timings: bool = True) -> dict:
        """The ``model.json`` form: the structure (functions by import
        path; a lambda or closure is refused in one line), every
        parameter's value and interval."""
        return dict(
            model="greybox",
            structure=self.structure.to_dict(),
            values=self.values.tolist(),
            intervals=[[float(a), float(b)] for a, b in self.intervals],
            undetermined=list(self.undetermined),
            ts=float(self.ts),
            method=str(self.method),
            cost=float(self.cost),
            output_name=_plain(self.output_name),
            nfev=int(self.nfev),
            output_fits={str(k): float(v) for k, v in self.output_fits.items()},
            weights=None if self.weights is None else self.weights.tolist(),
            column=self.column,
            **{name: _plain(getattr(self, name)) for name in _RECORD},
        )

    @classmethod
    def from_dict(cls, d: dict) -> GreyBoxModel:
        """The model :meth:`to_dict` wrote (the kind its structure names)."""
        if not isinstance(d, dict) or d.get("model") != "greybox":
            raise ValueError("a grey-box model file must have 'model': 'greybox'")
        try:
            structure = _structure_from_dict(d["structure"])
            kind = LinearGreyBoxModel if structure.kind == "linear" else GreyBoxModel
            return kind(
                structure=structure,
                values=np.asarray(d["values"], dtype=float),
                ts=float(d["ts"]),
                method=str(d["method"]),
                cost=float(d["cost"]),
                intervals=np.asarray(d["intervals"], dtype=float),
                undetermined=list(d.get("undetermined", [])),
                output_name=d.get("output_name", "y"),
                nfev=int(d.get("nfev", 0)),
                output_fits=dict(d.get("output_fits", {})),
                weights=d.get("weights"),
                column=d.get("column"),
                **{name: d[name] for name in _RECORD if name in d},
            )
        except KeyError as missing:
            raise ValueError(
                f"grey-box model file: field {missing} is missing"
            ) from None

    def __repr__(self) -> str:
        values = ", ".join(
            f"{n}={v:.4g}"
            for n, v in zip(self.structure.names, self.values, strict=True)
        )
        return f"{type(self).__name__}({values}; {self.method})"


class LinearGreyBoxModel(GreyBoxModel):
    """A fitted linear grey box: a :class:`GreyBoxModel` with the linear
    members, read from its exact zero-order-hold discretisation at the
    model's sample time.

    Parameters
    ----------
    structure, values, ts, method, cost, intervals, undetermined, output_name, nfev
        As :class:`GreyBoxModel`'s attributes.
    input_name, input_unit, output_unit, u_offset, y_offset
        As :class:`GreyBoxModel`'s attributes.
    output_fits, weights, column
        As :class:`GreyBoxModel`'s attributes.
    """

    @property
    def is_linear(self) -> bool:
        return True

    @property
    def linear_part(self) -> LinearGreyBoxModel:
        """The model itself."""
        return self

    def _discrete(self):
        ad, bd, c, d = self.structure.discretise(self.values, self.ts)
        if self.column is not None:
            c, d = c[self.column : self.column + 1], d[self.column : self.column + 1]
        return ad, bd, c, d

    def _one_output(self, member: str) -> None:
        # Several sensors share the poles but each has its own numerator:
        # reading the first one would be a silently wrong transfer function.
        if self.column is None and len(self.output_names) > 1:
            raise ValueError(
                f"`{member}` of a grey box of {len(self.output_names)} outputs "
                f"{self.output_names} is one per output: read "
                f"output_model(name).{member}"
            )

    @property
    def polynomials(self) -> tuple[np.ndarray, np.ndarray]:
        """``(num, den)`` in ``z^-1`` of equal lengths, ``den[0] = 1``, of a
        one-output model (:meth:`output_model` gives each output's)."""
        self._one_output("polynomials")
        return _transfer_function(*self._discrete())

    @property
    def integrator(self) -> int:
        """The poles at ``z = 1`` the physics has by design: a rigid-body
        rotation, an integrating output (the hub angle from torque). An
        eigenvalue of the continuous ``A`` at 0 holds to exactly 1; a double
        one (a Jordan block) lands ``sqrt(eps)`` away, hence the tolerance
        :data:`INTEGRATOR_TOLERANCE` (a time constant above 2,000 s at
        0.002 s). The stability verdict is judged without them, as for an
        ARX fit's known integrators."""
        return int(np.sum(np.abs(self.poles - 1.0) < INTEGRATOR_TOLERANCE))

    @property
    def free_denominator(self) -> np.ndarray:
        """The denominator's ``a_1..a_n`` of the poles other than the
        :attr:`integrator`'s."""
        poles = self.poles
        free = poles[np.abs(poles - 1.0) >= INTEGRATOR_TOLERANCE]
        return np.real(np.poly(free))[1:]

    @property
    def poles(self) -> np.ndarray:
        """Poles in z: the eigenvalues of the discretised ``A``."""
        return np.linalg.eigvals(self._discrete()[0])

    @property
    def zeros(self) -> np.ndarray:
        """Finite zeros in z of the discretised one-output model
        (:meth:`output_model` gives each output's)."""
        self._one_output("zeros")
        num = np.trim_zeros(self.polynomials[0], "f")
        return np.roots(num) if num.size > 1 else np.zeros(0, dtype=complex)

    @property
    def is_stable(self) -> bool:
        """Every pole strictly inside the unit circle."""
        return bool(is_stable_polynomial(self.free_denominator))

    @property
    def modes(self) -> ModeTable:
        """The complex pole pairs as modes (no intervals on them: the
        intervals are the parameters')."""
        several = self.column is None and (self.structure.n_outputs or 1) > 1
        if not several:
            return mode_table(self.free_denominator, self.polynomials[0], self.ts)
        # One set of poles, a share in each sensor: a mode is the model's
        # where any sensor shows it, flagged only where every sensor flags it.
        tables = [self.output_model(k).modes for k in range(self.structure.n_outputs)]
        return dataclasses.replace(
            tables[0],
            share=np.max([t.share for t in tables], axis=0),
            cancelled=np.all([t.cancelled for t in tables], axis=0),
            spurious=np.all([t.spurious for t in tables], axis=0),
        )


def _transfer_function(ad, bd, c, d) -> tuple[np.ndarray, np.ndarray]:
    """``(num, den)`` in ``z^-1`` of a one-output sampled model: ``den`` the
    characteristic polynomial of `ad` and ``num`` the first ``n + 1`` terms
    of ``den`` times the Markov parameters ``d, c bd, c ad bd, ...``.

    SciPy's ``ss2tf`` forms each numerator coefficient as a difference of
    two characteristic polynomials' coefficients, so a coefficient that is
    zero by structure (a delay's leading zeros) comes out as rounding, and
    its root as a zero near 1e16. The Markov parameters of a delay line
    are exact zeros, so their product keeps them.
    """
    den = np.real(np.poly(ad))
    n = den.size - 1
    markov = np.empty(n + 1)
    markov[0] = d[0, 0]
    reach = bd[:, 0]
    for k in range(1, n + 1):
        markov[k] = c[0] @ reach
        reach = ad @ reach
    num = np.convolve(den, markov)[: n + 1]
    return num, den
