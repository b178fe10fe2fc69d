"""Grey-box structures: a continuous-time model of named physical
parameters, simulated at a record's sample time with the input held
between samples.

Two kinds, as MATLAB's ``idgrey`` and ``idnlgrey``:

- linear: ``ss(p) -> (A, B, C, D)``, discretised exactly (zero-order hold:
  the matrix exponential of the augmented matrix ``[[A, B], [0, 0]] ts``)
  for each parameter vector;
- nonlinear: ``f(t, x, u, p) -> dx/dt`` and ``g(x, u, p) -> y`` with
  ``n_states`` states, integrated by fixed-step fourth-order Runge-Kutta
  with ``substeps`` steps per sample (``u`` held over the sample).

``p`` is every parameter's value in the declared order, free and fixed
alike (``k, c, m = p`` unpacks it), ``x`` and ``u`` one-dimensional arrays
(``u`` of length ``n_inputs``). A plain Python function works; a Numba one
is called the same way. Each function is called once at construction on
the initial values, and a wrong shape or a NaN is refused there in one line
naming the function.

A run that blows up returns non-finite outputs from the sample it left the
floating-point range on: the estimation's cost turns them into its penalty
and the search goes on.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numba
import numpy as np
from scipy import linalg

__all__ = ["GreyBox", "Parameter"]


@dataclass(frozen=True)
class Parameter:
    """One physical parameter of a :class:`GreyBox`.

    Parameters
    ----------
    name : str
        A Python identifier, unique in its model.
    value : float
        Initial value (the start of a local fit, the value of a fixed one),
        inside `bounds`.
    bounds : (float, float)
        Finite ``(low, high)`` with ``low < high``: the box a search
        covers.
    unit : str
        Its unit, shown with its value and interval.
    free : bool, default True
        Estimated (True) or held at `value`.
    log : bool, optional
        Searched in ``log(value)``: the default where ``low > 0`` (a
        positive quantity spanning decades), refused where ``low <= 0``.
    """

    name: str
    value: float
    bounds: tuple[float, float]
    unit: str = ""
    free: bool = True
    log: bool | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(
                f"a parameter's `name` must be a Python identifier; got {self.name!r}"
            )
        try:
            low, high = (float(b) for b in self.bounds)
            value = float(self.value)
        except (TypeError, ValueError):
            raise ValueError(
                f"parameter {self.name!r}: `value` must be a number and `bounds` two "
                f"numbers (low, high); got {self.value!r}, {self.bounds!r}"
            ) from None
        if not (math.isfinite(low) and math.isfinite(high)):
            raise ValueError(
                f"parameter {self.name!r}: `bounds` must be finite; got ({low}, {high})"
            )
        if not low < high:
            raise ValueError(
                f"parameter {self.name!r}: `bounds` must have low < high; got "
                f"({low}, {high})"
            )
        if not low <= value <= high:
            raise ValueError(
                f"parameter {self.name!r}: initial `value` {value} is outside its "
                f"bounds ({low}, {high})"
            )
        log = low > 0 if self.log is None else bool(self.log)
        if log and low <= 0:
            raise ValueError(
                f"parameter {self.name!r}: a log scale needs a lower bound > 0; got "
                f"{low}"
            )
        object.__setattr__(self, "bounds", (low, high))
        object.__setattr__(self, "value", value)
        object.__setattr__(self, "log", log)
        object.__setattr__(self, "free", bool(self.free))
        object.__setattr__(self, "unit", str(self.unit))

    def to_dict(self) -> dict:
        """The JSON form: every field by name."""
        return dict(
            name=self.name,
            value=self.value,
            bounds=list(self.bounds),
            unit=self.unit,
            free=self.free,
            log=self.log,
        )


def _function_name(fun: Callable) -> str:
    return getattr(fun, "__qualname__", None) or type(fun).__name__


class GreyBox:
    """A continuous-time model of physical parameters (see the module
    docstring): the structure :func:`~spiralid.sysid.identify` fits.

    Parameters
    ----------
    parameters : sequence of Parameter
        The model's parameters in the order its functions read ``p``.
    ss : callable, optional
        ``ss(p) -> (A, B, C, D)``: the linear kind.
    f, g : callable, optional
        ``f(t, x, u, p) -> dx/dt`` and ``g(x, u, p) -> y``: the nonlinear
        kind (with `n_states`).
    n_states : int, optional
        The nonlinear kind's state dimension.
    n_inputs : int, default 1
        The nonlinear kind's input dimension (the linear kind's is ``B``'s
        columns).
    x0 : array_like, optional
        Initial state (zero by default).
    substeps : int, default 10
        Runge-Kutta steps per sample (nonlinear kind).

    Attributes
    ----------
    family : str
        ``"greybox"``, its key in the estimator table.
    kind : str
        ``"linear"`` or ``"nonlinear"``.
    n_outputs : int
        The output dimension (one: the family fits records of one output).
    """

    family = "greybox"
    outputs_family = None
    # A grey box reads no past outputs: it runs from its own state.
    max_lag = 0

    def __init__(
        self,
        parameters: Sequence[Parameter],
        *,
        ss: Callable | None = None,
        f: Callable | None = None,
        g: Callable | None = None,
        n_states: int | None = None,
        n_inputs: int = 1,
        x0=None,
        substeps: int = 10,
    ) -> None:
        params = tuple(parameters)
        if not params or not all(isinstance(p, Parameter) for p in params):
            raise TypeError(
                "`parameters` must be a non-empty sequence of Parameter; got "
                f"{type(parameters).__name__}"
            )
        names = [p.name for p in params]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ValueError(f"`parameters` names {twice} more than once")
        if (ss is None) == (f is None):
            raise ValueError("a GreyBox takes either `ss` (linear) or `f` and `g`")
        self.parameters = params
        self.substeps = int(substeps)
        if self.substeps < 1:
            raise ValueError(f"`substeps` must be >= 1; got {substeps!r}")
        values = self.initial_values
        if ss is not None:
            if not callable(ss):
                raise TypeError(f"`ss` must be callable; got {type(ss).__name__}")
            self.kind = "linear"
            self.functions = {"ss": ss}
            a, b, c, _ = self.matrices(values)
            self.n_states, self.n_inputs, self.n_outputs = (
                a.shape[0],
                b.shape[1],
                c.shape[0],
            )
        else:
            for name, fun in (("f", f), ("g", g)):
                if not callable(fun):
                    raise TypeError(
                        f"`{name}` must be callable; got {type(fun).__name__}"
                    )
            if n_states is None or int(n_states) < 1:
                raise ValueError(
                    f"the nonlinear kind needs `n_states` >= 1; got {n_states!r}"
                )
            self.kind = "nonlinear"
            self.functions = {"f": f, "g": g}
            self.n_states, self.n_inputs = int(n_states), int(n_inputs)
            self.n_outputs = None
        self.x0 = self._initial_state(x0)
        if self.kind == "nonlinear":
            u0 = np.zeros(self.n_inputs)
            self._derivative(0.0, self.x0, u0, values)
            self.n_outputs = self._output(self.x0, u0, values, size=None).size
        if self.n_outputs != 1:
            raise ValueError(
                f"the grey-box family fits one output; `{self._output_function}` "
                f"returns {self.n_outputs}"
            )

    # -- the parameters -------------------------------------------------------

    @property
    def names(self) -> tuple[str, ...]:
        """Every parameter's name, in order."""
        return tuple(p.name for p in self.parameters)

    @property
    def initial_values(self) -> np.ndarray:
        """Every parameter's initial value, in order."""
        return np.array([p.value for p in self.parameters])

    @property
    def free(self) -> np.ndarray:
        """Which parameters are estimated (boolean mask)."""
        return np.array([p.free for p in self.parameters])

    @property
    def _output_function(self) -> str:
        return "ss" if self.kind == "linear" else "g"

    def _initial_state(self, x0) -> np.ndarray:
        if x0 is None:
            return np.zeros(self.n_states)
        x = np.asarray(x0, dtype=float).ravel()
        if x.size != self.n_states or not np.all(np.isfinite(x)):
            raise ValueError(
                f"`x0` must be {self.n_states} finite numbers; got {np.asarray(x0)!r}"
            )
        return x

    # -- the functions, checked -----------------------------------------------

    def matrices(self, values) -> tuple[np.ndarray, ...]:
        """``(A, B, C, D)`` at the parameter values `values` (linear kind),
        as float arrays of consistent shapes, or a one-line ValueError
        naming ``ss``."""
        name = _function_name(self.functions["ss"])
        try:
            out = self.functions["ss"](values)
            a, b, c, d = (np.atleast_2d(np.asarray(m, dtype=float)) for m in out)
        except (TypeError, ValueError) as error:
            raise ValueError(
                f"`ss` ({name}) must return four matrices (A, B, C, D); {error}"
            ) from None
        n = a.shape[0]
        if b.shape[0] != n and b.shape[1] == n and b.shape[0] == 1:
            b = b.T  # a column given as a row
        shapes_ok = (
            a.shape == (n, n)
            and b.shape[0] == n
            and c.shape[1:] == (n,)
            and d.shape == (c.shape[0], b.shape[1])
        )
        if not shapes_ok:
            raise ValueError(
                f"`ss` ({name}) returned A {a.shape}, B {b.shape}, C {c.shape}, "
                f"D {d.shape}: want (n, n), (n, m), (p, n), (p, m)"
            )
        for label, m in zip("ABCD", (a, b, c, d), strict=True):
            if not np.all(np.isfinite(m)):
                raise ValueError(
                    f"`ss` ({name}) returned a non-finite {label} at p = {values}"
                )
        return a, b, c, d

    def _derivative(self, t, x, u, values) -> np.ndarray:
        name = _function_name(self.functions["f"])
        dx = np.asarray(self.functions["f"](t, x, u, values), dtype=float)
        if dx.shape != (self.n_states,):
            raise ValueError(
                f"`f` ({name}) must return dx/dt of shape ({self.n_states},); got "
                f"shape {dx.shape}"
            )
        if not np.all(np.isfinite(dx)):
            raise ValueError(f"`f` ({name}) returned a non-finite dx/dt at x0")
        return dx

    def _output(self, x, u, values, size) -> np.ndarray:
        name = _function_name(self.functions["g"])
        y = np.atleast_1d(np.asarray(self.functions["g"](x, u, values), dtype=float))
        if y.ndim != 1 or (size is not None and y.size != size):
            raise ValueError(f"`g` ({name}) must return y of shape (p,); got {y.shape}")
        if not np.all(np.isfinite(y)):
            raise ValueError(f"`g` ({name}) returned a non-finite y at x0")
        return y

    # -- simulation -------------------------------------------------------------

    def discretise(self, values, ts: float) -> tuple[np.ndarray, ...]:
        """The linear kind's ``(Ad, Bd, C, D)`` at sample time `ts`, input
        held between samples (exact zero-order hold)."""
        a, b, c, d = self.matrices(values)
        n, m = b.shape
        big = np.zeros((n + m, n + m))
        big[:n, :n], big[:n, n:] = a, b
        phi = linalg.expm(big * ts)
        return (
            np.ascontiguousarray(phi[:n, :n]),
            np.ascontiguousarray(phi[:n, n:]),
            np.ascontiguousarray(c),
            np.ascontiguousarray(d),
        )

    def simulate(self, values, u, ts: float) -> np.ndarray:
        """The output, shape (N,), over the input `u` (shape (N,) or (N,
        m)) from the initial state at the parameter values `values` (every
        parameter, in order); non-finite from where the run blew up."""
        values = np.asarray(values, dtype=float)
        uu = np.asarray(u, dtype=float).reshape(len(u), -1)
        if uu.shape[1] != self.n_inputs:
            raise ValueError(
                f"`u` must have {self.n_inputs} input column(s); got {uu.shape[1]}"
            )
        with np.errstate(all="ignore"):
            if self.kind == "linear":
                try:
                    ad, bd, c, d = self.discretise(values, ts)
                except ValueError:
                    # Parameters where ss itself fails: no run, the penalty.
                    return np.full(uu.shape[0], np.nan)
                return _lti_run(ad, bd, c, d, self.x0, uu)[:, 0]
            return self._rk4(values, uu, ts)

    def _rk4(self, values, uu: np.ndarray, ts: float) -> np.ndarray:
        f, g = self.functions["f"], self.functions["g"]
        h = ts / self.substeps
        x = self.x0.copy()
        y = np.full(uu.shape[0], np.nan)
        for k in range(uu.shape[0]):
            uk = uu[k]
            y[k] = np.asarray(g(x, uk, values), dtype=float).ravel()[0]
            t = k * ts
            for _ in range(self.substeps):
                k1 = np.asarray(f(t, x, uk, values), dtype=float)
                k2 = np.asarray(f(t + h / 2, x + h / 2 * k1, uk, values), dtype=float)
                k3 = np.asarray(f(t + h / 2, x + h / 2 * k2, uk, values), dtype=float)
                k4 = np.asarray(f(t + h, x + h * k3, uk, values), dtype=float)
                x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
                t += h
            if not np.all(np.isfinite(x)):
                break  # the rest stays NaN: the cost's penalty
        return y

    # -- text and JSON ------------------------------------------------------------

    def function_paths(self) -> dict[str, str]:
        """Each function's import path ``module:qualname``, or a one-line
        ValueError for a lambda or a closure, which no path names."""
        out = {}
        for role, fun in self.functions.items():
            qualname = getattr(fun, "__qualname__", "")
            module = getattr(fun, "__module__", None)
            if not module or not qualname or "<" in qualname:
                raise ValueError(
                    f"the grey box's `{role}` ({qualname or type(fun).__name__}) is a "
                    "lambda or closure, which model.json cannot name: define it at a "
                    "module's top level to save the model"
                )
            out[role] = f"{module}:{qualname}"
        return out

    def to_dict(self) -> dict:
        """The JSON form (functions by import path, see
        :meth:`function_paths`)."""
        return dict(
            kind=self.kind,
            functions=self.function_paths(),
            parameters=[p.to_dict() for p in self.parameters],
            n_states=self.n_states,
            n_inputs=self.n_inputs,
            x0=self.x0.tolist(),
            substeps=self.substeps,
        )

    @classmethod
    def from_dict(cls, d: dict) -> GreyBox:
        """The structure :meth:`to_dict` wrote, its functions imported.

        The file names each function's module, which this imports and
        runs (as unpickling would): read only model files you trust.
        """
        functions = {role: _import(path) for role, path in d["functions"].items()}
        params = [Parameter(**p) for p in d["parameters"]]
        extra = {}
        if d["kind"] == "nonlinear":
            extra = dict(n_states=int(d["n_states"]), n_inputs=int(d["n_inputs"]))
        return cls(
            params, x0=d.get("x0"), substeps=int(d.get("substeps", 10)), **functions,
            **extra,
        )  # fmt: skip

    def __repr__(self) -> str:
        funs = ", ".join(f"{k}={_function_name(v)}" for k, v in self.functions.items())
        return f"GreyBox({self.kind}: {funs}; {', '.join(self.names)})"

    __str__ = __repr__


def _import(path: str) -> Callable:
    """The object a ``module:qualname`` path names, or a one-line
    ValueError."""
    import importlib

    module, _, qualname = str(path).partition(":")
    try:
        obj = importlib.import_module(module)
        for part in qualname.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError, ValueError) as error:
        raise ValueError(
            f"the grey box's function {path!r} cannot be imported: {error}"
        ) from None
    return obj


@numba.njit(cache=True)
def _lti_run(ad, bd, c, d, x0, u):  # pragma: no cover - compiled
    """``x[k+1] = Ad x[k] + Bd u[k]``, ``y[k] = C x[k] + D u[k]`` from
    `x0`; NaN after the state leaves the floating-point range."""
    n_samples = u.shape[0]
    y = np.full((n_samples, c.shape[0]), np.nan)
    x = x0.copy()
    for k in range(n_samples):
        y[k] = c @ x + d @ u[k]
        x = ad @ x + bd @ u[k]
        if not np.all(np.isfinite(x)):
            break
    return y
