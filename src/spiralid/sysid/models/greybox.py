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
(``u`` of length ``n_inputs``). Several outputs are ``C``'s rows, or the
values ``g`` returns: a record of as many outputs, in that order, is fitted
by all of them at once (each weighted by its noise variance, see
:mod:`spiralid.sysid.estimation.greybox.fit`). A plain Python function works; with Numba
functions (``numba.njit``) for both ``f`` and ``g`` the Runge-Kutta loop
runs compiled (:mod:`.greybox_run`). Each function is called once at
construction on the initial values, and a wrong shape or a NaN is refused
there in one line naming the function.

The initial state is zero, given, or estimated: an entry of ``x0`` given
as a :class:`Parameter` joins the parameters (after the functions' ones,
never in ``p``), searched and given an interval as they are.

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

from spiralid._checks import integer

from .greybox_run import is_compiled, lti_run, rk4_compiled, rk4_python, zoh

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


def _is_sequence(obj) -> bool:
    return isinstance(obj, Sequence | np.ndarray) and not isinstance(obj, str)


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
    x0 : sequence of float or Parameter, optional
        Initial state, zero by default: one entry per state, a number
        (given) or a :class:`Parameter` (estimated with the model's
        parameters if free, within its bounds, as ``idnlgrey``'s initial
        states; held at its value if fixed).
    substeps : int, default 10
        Runge-Kutta steps per sample (nonlinear kind).

    Attributes
    ----------
    family : str
        ``"greybox"``, its key in the estimator table.
    kind : str
        ``"linear"`` or ``"nonlinear"``.
    n_outputs : int
        The output dimension: ``C``'s rows, or the values ``g`` returns.
    parameters : tuple of Parameter
        The functions' parameters (``p``).
    state_parameters : tuple of Parameter
        The initial state's parameters, in state order (the entries of `x0`
        given as :class:`Parameter`).
    all_parameters : tuple of Parameter
        Both, the functions' first: the vector ``values`` that
        :meth:`simulate` and a fitted model's ``values`` hold.
    """

    family = "greybox"
    # Several outputs are the structure's own (``g``'s values, ``C``'s rows).
    outputs_family = "greybox"
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
        params = tuple(parameters) if _is_sequence(parameters) else ()
        if not params or not all(isinstance(p, Parameter) for p in params):
            raise TypeError(
                "`parameters` must be a non-empty sequence of Parameter; got "
                f"{type(parameters).__name__}"
            )
        if (ss is None) == (f is None):
            raise ValueError("a GreyBox takes either `ss` (linear) or `f` and `g`")
        self.parameters = params
        self.state_parameters: tuple[Parameter, ...] = ()
        self.substeps = integer(substeps, "substeps", 1)
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
            if n_states is None:
                raise ValueError("the nonlinear kind needs `n_states` >= 1; got None")
            self.kind = "nonlinear"
            self.functions = {"f": f, "g": g}
            self.n_states = integer(n_states, "n_states", 1)
            self.n_inputs = integer(n_inputs, "n_inputs", 1)
            self.n_outputs = None
        self._x0_given = self._initial_state(x0)
        names = list(self.names)
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise ValueError(
                f"`parameters` and `x0` name {twice} more than once: each "
                "parameter needs its own name"
            )
        if self.kind == "nonlinear":
            u0 = np.zeros(self.n_inputs)
            self._derivative(0.0, self.x0, u0, values)
            self.n_outputs = self._output(self.x0, u0, values, size=None).size

    # -- the parameters -------------------------------------------------------

    @property
    def all_parameters(self) -> tuple[Parameter, ...]:
        return self.parameters + self.state_parameters

    @property
    def names(self) -> tuple[str, ...]:
        """Every parameter's name (:attr:`all_parameters`), in order."""
        return tuple(p.name for p in self.all_parameters)

    @property
    def initial_values(self) -> np.ndarray:
        """Every parameter's initial value (:attr:`all_parameters`), in
        order."""
        return np.array([p.value for p in self.all_parameters])

    @property
    def free(self) -> np.ndarray:
        """Which of :attr:`all_parameters` are estimated (boolean mask)."""
        return np.array([p.free for p in self.all_parameters])

    @property
    def x0(self) -> np.ndarray:
        """The initial state at the initial values."""
        return self.initial_state(self.initial_values)

    def initial_state(self, values) -> np.ndarray:
        """The initial state at `values` (every parameter, as
        :meth:`simulate` takes them)."""
        x = self._x0_given.copy()
        n_p = len(self.parameters)
        if len(values) > n_p:
            x[self._x0_free_rows] = np.asarray(values, dtype=float)[n_p:]
        return x

    def output_source(self) -> str:
        """What gives the outputs, for messages: the function by role and
        name."""
        role = "ss" if self.kind == "linear" else "g"
        return f"`{role}` ({_function_name(self.functions[role])})"

    def _initial_state(self, x0) -> np.ndarray:
        """The given initial state (a Parameter's entry at its value), the
        Parameters kept in :attr:`state_parameters`."""
        self._x0_free_rows = np.zeros(0, dtype=int)
        if x0 is None:
            return np.zeros(self.n_states)
        entries = list(x0) if _is_sequence(x0) else [x0]
        rows = [i for i, e in enumerate(entries) if isinstance(e, Parameter)]
        self.state_parameters = tuple(entries[i] for i in rows)
        self._x0_free_rows = np.array(rows, dtype=int)
        numbers = [e.value if isinstance(e, Parameter) else e for e in entries]
        try:
            x = np.asarray(numbers, dtype=float).ravel()
        except (TypeError, ValueError):
            x = np.full(0, np.nan)
        if x.size != self.n_states or not np.all(np.isfinite(x)):
            raise ValueError(
                f"`x0` must be {self.n_states} finite numbers or Parameters; got {x0!r}"
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
        dx = _called("f", name, self.functions["f"], t, x, u, values)
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
        y = np.atleast_1d(_called("g", name, self.functions["g"], x, u, values))
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
        ad, bd = zoh(np.ascontiguousarray(a), np.ascontiguousarray(b), float(ts))
        return ad, bd, np.ascontiguousarray(c), np.ascontiguousarray(d)

    def simulate(self, values, u, ts: float) -> np.ndarray:
        """The output, shape (N,) (one output) or (N, p), over the input
        `u` (shape (N,) or (N, m)) from the initial state at the parameter
        values `values` (every parameter of :attr:`all_parameters`, in
        order, or only the functions', the initial state then at its
        initial values); non-finite from where the run blew up.

        With Numba functions ``f`` and ``g`` the Runge-Kutta loop runs
        compiled (:mod:`.greybox_run`), otherwise in Python; the two agree
        to rounding.
        """
        values = np.asarray(values, dtype=float).ravel()
        n_p = len(self.parameters)
        if values.size not in (n_p, n_p + len(self.state_parameters)):
            raise ValueError(
                f"`values` must hold {n_p} or {len(self.names)} numbers (the "
                f"parameters {self.names}); got {values.size}"
            )
        uu = np.ascontiguousarray(np.asarray(u, dtype=float).reshape(len(u), -1))
        if uu.shape[1] != self.n_inputs:
            raise ValueError(
                f"`u` must have {self.n_inputs} input column(s); got {uu.shape[1]}"
            )
        p, x0 = np.ascontiguousarray(values[:n_p]), self.initial_state(values)
        y = self._run(p, x0, uu, float(ts))
        return y[:, 0] if self.n_outputs == 1 else y

    def _run(self, p, x0, uu, ts: float) -> np.ndarray:
        """The outputs, shape (N, p), of :meth:`simulate`."""
        with np.errstate(all="ignore"):
            if self.kind == "linear":
                try:
                    ad, bd, c, d = self.discretise(p, ts)
                except ValueError:
                    # Parameters where ss itself fails: no run, the penalty.
                    return np.full((uu.shape[0], self.n_outputs), np.nan)
                return lti_run(ad, bd, c, d, x0, uu)
            f, g = self.functions["f"], self.functions["g"]
            n_out = self.n_outputs
            if not is_compiled(f, g):
                return rk4_python(f, g, p, x0, uu, ts, self.substeps, n_out)
            try:
                return rk4_compiled(f, g, p, x0, uu, ts, self.substeps, n_out)
            except numba.core.errors.TypingError as error:
                first = str(error).strip().splitlines()[-1][:200]
                raise ValueError(
                    f"the Numba functions `f` ({_function_name(f)}) and `g` "
                    f"({_function_name(g)}) do not compile in the Runge-Kutta "
                    f"loop (f must return a float array of the states, g a "
                    f"number or an array of the outputs): {first}"
                ) from None

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
            x0=self._x0_entries(),
            substeps=self.substeps,
        )

    def _x0_entries(self) -> list:
        """The initial state as `x0` takes it: numbers, and the estimated
        entries as Parameters' JSON forms."""
        out: list = self._x0_given.tolist()
        for row, p in zip(self._x0_free_rows, self.state_parameters, strict=True):
            out[row] = p.to_dict()
        return out

    @classmethod
    def from_dict(cls, d: dict) -> GreyBox:
        """The structure :meth:`to_dict` wrote, its functions imported.

        The file names each function's module, which this imports and
        runs (as unpickling would): read only model files you trust.
        """
        functions = {role: _import(path) for role, path in d["functions"].items()}
        params = [Parameter(**p) for p in d["parameters"]]
        x0 = d.get("x0")
        if x0 is not None:
            x0 = [Parameter(**e) if isinstance(e, dict) else e for e in x0]
        extra = {}
        if d["kind"] == "nonlinear":
            extra = dict(n_states=int(d["n_states"]), n_inputs=int(d["n_inputs"]))
        return cls(
            params, x0=x0, substeps=int(d.get("substeps", 10)), **functions,
            **extra,
        )  # fmt: skip

    def __repr__(self) -> str:
        funs = ", ".join(f"{k}={_function_name(v)}" for k, v in self.functions.items())
        return f"GreyBox({self.kind}: {funs}; {', '.join(self.names)})"

    __str__ = __repr__


def _called(role: str, name: str, fun: Callable, *args) -> np.ndarray:
    """``fun(*args)`` as a float array, or the same error type in one line
    naming the function (a wrong signature, a string returned)."""
    try:
        return np.asarray(fun(*args), dtype=float)
    except (TypeError, ValueError) as error:
        first = (str(error).strip().splitlines() or [""])[0][:160]
        raise type(error)(
            f"`{role}` ({name}) failed on the initial values and state: {first}"
        ) from None


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
