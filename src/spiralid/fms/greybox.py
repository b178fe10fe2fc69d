"""The rig as a ready grey box: :class:`RigGreyBox`, any subset of
:class:`~spiralid.fms.rig.FlexibleManipulator`'s physical fields free,
fitted by :func:`spiralid.sysid.identify` to a record of one or several of its
sensors.

Every evaluation builds the rig at the parameter values and runs the rig's
own sampled simulation (``FlexibleManipulator._outputs``): the exact
zero-order hold of the finite-element model for the linear rig, the
implicit stick-slip step of :mod:`spiralid.fms._friction` with hub
friction on, the amplifier's clip with a torque limit. Nothing of the
physics is restated here, so the grey box and the simulator that made a
record cannot drift apart.

Three options connect the rig to a record made elsewhere (a real arm):
``output_gain``, a factor between the rig's output in SI units and the
record's (a sensor's scale and sign), ``x0``, the modal initial state,
given or estimated (a record that starts in motion), and the parameter
``input_delay`` (named in ``free``), a delay in seconds between the
record's input and the torque the rig feels, fractional and of either
sign (a negative one an advance: a measured input, not a held one, leads
its zero-order hold by about half a sample), run by the exact sampled
model of the delayed, held input (:func:`spiralid.fms._zoh.discretise_delayed`).
:func:`spiralid.fms.greybox_start.rig_start_from_modes` picks a start whose
finite-element modes are those of a black box fitted to the record.

``n_modes`` keeps the rigid mode and the first ``n_modes`` flexible ones
(modal truncation): fewer states, so faster runs (the stick-slip step's
cost grows with the square of the state count), at the price of the
higher modes' share of the output.

This module is the one place where ``fms`` builds on ``sysid`` (the grey-box
family); ``sysid`` never imports ``fms``: a saved model names this class by
its import path, which :func:`spiralid.sysid.load_model` follows.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from spiralid._checks import integer, one_of
from spiralid.choices import RIG_PARAMETERS
from spiralid.fms._zoh import (
    delay_split,
    delayed_inputs,
    delayed_system,
    discretise_delayed,
)
from spiralid.fms.rig import _OUTPUTS, FlexibleManipulator, _continuous, _discrete
from spiralid.fms.sensors import Sensors
from spiralid.sysid.models.greybox import GreyBox, Parameter
from spiralid.sysid.models.greybox_run import lti_run

__all__ = ["DELAY", "GAIN", "RIG_PARAMETERS", "RigGreyBox", "default_parameter"]

#: The name of the output gain's parameter (not a field of the rig).
GAIN = "output_gain"
#: The name of the input delay's parameter (in ``free``; not a field of the
#: rig): seconds between the record's input and the rig's torque.
DELAY = "input_delay"
# Its default bounds (s): a sample either way at 0.01 s, a common record's.
_DELAY_BOUNDS = (-0.01, 0.01)

# The derived parameters and the fields they are computed from: freeing one
# with any of its fields would leave a direction the model cannot see.
_DERIVED = {
    "flexural_rigidity": ("youngs_modulus", "width", "thickness"),
    "mass_per_length": ("density", "width", "thickness"),
}
# The fields that make the rig nonlinear (the friction step, the clip).
_NONLINEAR = (
    "coulomb_friction",
    "static_friction",
    "stribeck_velocity",
    "torque_limit",
)
# Default bounds: a factor either side of the preset, on a log scale.
_FACTOR = 4.0
# The outputs read through no anti-aliasing filter: the encoder's count and
# the exact deflections.
_UNFILTERED = ("hub_angle", "tip_deflection")


def _value(rig: FlexibleManipulator, name: str) -> float | None:
    if name == "mass_per_length":
        return float(rig.density * rig.area)
    value = getattr(rig, name)
    return None if value is None else float(value)


def _zero_preset_high(rig: FlexibleManipulator, name: str) -> float:
    """The upper bound of a field whose preset is zero (our choice, a
    scale of the rig): a payload up to the beam's mass or its inertia about
    the hub, friction torques up to 0.1 N m (a third of the paper's
    pulses), a viscous friction that would stop the rigid rig in 0.1 s and
    Rayleigh coefficients that alone give the first flexible mode a damping
    ratio of 0.5."""
    beam_mass = rig.density * rig.area * rig.length
    w1 = 2.0 * np.pi * float(rig.modes(1)[0])
    return {
        "mass_damping": w1,
        "stiffness_damping": 1.0 / w1,
        "payload_mass": beam_mass,
        "payload_inertia": beam_mass * rig.length**2 / 3.0,
        "coulomb_friction": 0.1,
        "static_friction": 0.1,
        "hub_friction": 10.0 * rig.total_inertia,
    }[name]


def default_parameter(rig: FlexibleManipulator, name: str) -> Parameter:
    """The free parameter `name` (a key of :data:`RIG_PARAMETERS`) at its
    value on `rig`: bounds a factor 4 either side on a log scale, or from
    zero up to a scale of the rig where the preset is zero; the input delay
    from 0 within 0.01 s either way.

    Parameters
    ----------
    rig : FlexibleManipulator
        The rig whose value starts the parameter.
    name : str
        The field.

    Returns
    -------
    Parameter
    """
    one_of(name, "free", RIG_PARAMETERS)
    unit = RIG_PARAMETERS[name]
    if name == DELAY:
        return Parameter(name, 0.0, _DELAY_BOUNDS, unit)
    value = _value(rig, name)
    if value is None:
        raise ValueError(
            f"`free`: {name} is None on the rig (no limit): give it as a "
            "Parameter with a value and bounds"
        )
    if value > 0.0:
        high = value * _FACTOR
        if name == "damping_ratio":
            high = min(high, 0.95)  # the field must stay below 1
        return Parameter(name, value, (value / _FACTOR, high), unit)
    return Parameter(name, 0.0, (0.0, _zero_preset_high(rig, name)), unit)


def _outputs_of(output, sensors: Sensors) -> tuple[str | tuple, tuple[str, ...]]:
    """`output` checked (one sensor or several, each once): as given (a
    tuple for several) and as a tuple."""
    known = _OUTPUTS + sensors.positional_names
    if isinstance(output, str):
        return one_of(output, "output", known), (output,)
    names = tuple(output) if isinstance(output, Sequence) else ()
    if not names or not all(isinstance(n, str) for n in names):
        raise TypeError(
            f"`output` must be a sensor's name or a sequence of them; got {output!r}"
        )
    for name in names:
        one_of(name, "output", known)
    if len(set(names)) != len(names):
        raise ValueError(f"`output` must name each sensor once; got {names}")
    return (names[0] if len(names) == 1 else names), names


class RigGreyBox(GreyBox):
    """The flexible manipulator as a grey box: the fields named in `free`
    estimated, the others held at `rig`'s values.

    Parameters
    ----------
    free : sequence of str or Parameter
        The fields to estimate, each a key of :data:`RIG_PARAMETERS`; a name
        takes :func:`default_parameter`'s value and bounds, a
        :class:`~spiralid.sysid.Parameter` of such a name its own (and with
        ``free=False`` just sets the field). ``"input_delay"`` (s) delays
        the record's input before the rig (negative: an advance, above one
        sample; fractional delays exact for the held input); the linear
        kind only.
    rig : FlexibleManipulator, optional
        The rig whose other fields are held and whose values start the
        free ones; default ``FlexibleManipulator()``.
    output : str or sequence of str, default "hub_angle"
        The sensor the record holds: ``"hub_angle"``, ``"hub_velocity"``,
        ``"end_acceleration"``, ``"tip_deflection"``, or one of `sensors`'
        positional outputs (``deflection_<x>``, ``acceleration_<x>``); or
        several of them, the record's outputs in that order (each weighted
        by its noise variance in the fit).
    n_modes : int, optional
        Keep the rigid mode and this many flexible modes (default all
        ``2 n_elements``).
    sensors : Sensors, optional
        The instruments (their anti-aliasing filter is part of the model of
        a filtered channel; noise and quantisation are not); default
        ``Sensors()``, the rig's.
    output_gain : float or Parameter, optional
        The record's output per unit of the rig's (SI) output: a number
        holds it, a :class:`~spiralid.sysid.Parameter` named
        ``"output_gain"`` estimates it within its bounds (a negative range
        for a sensor of the opposite sign). Default 1, no parameter. With
        every mass and stiffness free it trades against their common scale
        (the record cannot tell them apart): hold one of those.
    x0 : sequence of float or Parameter, optional
        The initial state in the model's coordinates, ``n_states`` entries
        (modal displacements, then scaled modal velocities, then the
        filter's states; see :meth:`modal_state`), each a number or an
        estimated :class:`~spiralid.sysid.Parameter` as
        :class:`~spiralid.sysid.GreyBox` takes them; default rest. The
        linear kind only.

    Attributes
    ----------
    outputs : tuple of str
        The sensors, in the record's order (`output` given as one name or
        several).
    kind : str
        ``"nonlinear"`` when friction or a torque limit is on or free, else
        ``"linear"`` (the fit then has poles and modes).

    Examples
    --------
    >>> box = RigGreyBox(["flexural_rigidity", "hub_inertia"], n_modes=3)
    >>> box.kind, box.names, box.n_states
    ('linear', ('flexural_rigidity', 'hub_inertia'), 8)
    """

    def __init__(
        self,
        free: Sequence[str | Parameter],
        rig: FlexibleManipulator | None = None,
        *,
        output: str | Sequence[str] = "hub_angle",
        n_modes: int | None = None,
        sensors: Sensors | None = None,
        output_gain: float | Parameter = 1.0,
        x0=None,
    ) -> None:
        rig = FlexibleManipulator() if rig is None else rig
        if not isinstance(rig, FlexibleManipulator):
            raise TypeError(
                f"`rig` must be a FlexibleManipulator; got {type(rig).__name__}"
            )
        sensors = Sensors() if sensors is None else sensors
        if not isinstance(sensors, Sensors):
            raise TypeError(
                f"`sensors` must be a Sensors; got {type(sensors).__name__}"
            )
        if isinstance(free, str) or not isinstance(free, Sequence) or not free:
            raise TypeError(
                "`free` must be a non-empty list of field names or Parameters; "
                f"got {free!r}"
            )
        self.parameters = tuple(self._parameter(rig, p) for p in free)
        self._n_fields = len(self.parameters)
        self.output_gain = self._gain(output_gain)
        if isinstance(self.output_gain, Parameter):
            self.parameters += (self.output_gain,)
        names = [p.name for p in self.parameters]
        if len(set(names)) != len(names):
            raise ValueError(f"`free` names a field more than once: {names}")
        for derived, parts in _DERIVED.items():
            clash = [n for n in parts if n in names]
            if derived in names and clash:
                raise ValueError(
                    f"`free`: {derived} is computed from {', '.join(clash)}; free "
                    "one or the other"
                )
        self.rig, self.sensors = rig, sensors
        self.output, self.outputs = _outputs_of(output, sensors)
        known = _OUTPUTS + sensors.positional_names
        self._rows = [known.index(name) for name in self.outputs]
        if n_modes is not None:
            n_modes = integer(n_modes, "n_modes", 1)
            if n_modes > 2 * rig.n_elements:
                raise ValueError(
                    f"`n_modes` must be at most 2 n_elements = {2 * rig.n_elements}; "
                    f"got {n_modes}"
                )
        self.n_modes = n_modes
        # The encoder and the deflections pass no filter: the model runs
        # without the other channels' filter states.
        unfiltered = all(n in _UNFILTERED or n.startswith("defl") for n in self.outputs)
        self._sim_sensors = (
            dataclasses.replace(sensors, antialias_order=0) if unfiltered else sensors
        )
        nonlinear = rig.has_friction or rig.torque_limit is not None
        self.kind = (
            "nonlinear" if nonlinear or set(names) & set(_NONLINEAR) else "linear"
        )
        self._delay_at = names.index(DELAY) if DELAY in names else None
        if self._delay_at is not None and self.kind == "nonlinear":
            raise ValueError(
                "`free`: input_delay needs the linear rig (no friction, no torque "
                "limit)"
            )
        self.functions = {}
        self.substeps = rig.friction_substeps
        self.n_inputs, self.n_outputs = 1, len(self.outputs)
        self.state_parameters = ()
        a = self.matrices(self.initial_values, 1.0)[0]
        self.n_states = a.shape[0]
        # By default the record starts at rest, as the rig's simulate does.
        self._x0_given = self._initial_state(x0)
        if self.kind == "nonlinear" and (self.state_parameters or self._x0_given.any()):
            raise ValueError(
                "`x0`: an initial state other than rest needs the linear rig (no "
                "friction, no torque limit)"
            )
        twice = sorted({n for n in self.names if self.names.count(n) > 1})
        if twice:
            raise ValueError(f"`x0` names {twice} as a parameter already has")

    @staticmethod
    def _gain(value) -> float | Parameter:
        """`output_gain` checked: a finite nonzero number or a Parameter
        named :data:`GAIN`."""
        if isinstance(value, Parameter):
            if value.name != GAIN:
                raise ValueError(
                    f"`output_gain` as a Parameter must be named {GAIN!r}; got "
                    f"{value.name!r}"
                )
            return value
        if isinstance(value, bool) or not isinstance(value, int | float | np.number):
            raise TypeError(
                f"`output_gain` must be a number or a Parameter; got "
                f"{type(value).__name__}"
            )
        if not (np.isfinite(value) and value != 0.0):
            raise ValueError(f"`output_gain` must be finite and nonzero; got {value}")
        return float(value)

    def delay_at(self, values) -> float | None:
        """The input delay (s) at `values` (every parameter, in order), or
        None when `free` does not name it (the plain zero-order hold)."""
        if self._delay_at is None:
            return None
        return float(np.asarray(values, dtype=float)[self._delay_at])

    def gain_at(self, values) -> float:
        """The output gain at `values` (every parameter, in order)."""
        if isinstance(self.output_gain, Parameter):
            return float(np.asarray(values, dtype=float)[self._n_fields])
        return self.output_gain

    def modal_state(self, x) -> np.ndarray:
        """The model's state for the rig's generalised coordinates and
        velocities `x` (``(q, q')``, shape ``(2 ndof,)``, as
        :meth:`FlexibleManipulator.simulate` takes ``x0``), at the initial
        values: modal displacements ``eta`` with ``q = Phi eta``, velocities
        scaled by each flexible mode's frequency, the filter at rest.

        Parameters
        ----------
        x : array_like, shape (2 ndof,)
            The rig's state.

        Returns
        -------
        ndarray, shape (n_states,)
        """
        rig = self.rig_at(self.initial_values)
        x = np.asarray(x, dtype=float).ravel()
        if x.size != 2 * rig.ndof:
            raise ValueError(
                f"`x` must have 2 ndof = {2 * rig.ndof} entries; got {x.size}"
            )
        _, _, _, _, scale = rig._plant(n_modes=self.n_modes)
        n = scale.size
        phi, m = rig._modal[1][:, :n], rig.mass_matrix
        s = np.zeros(self.n_states)
        s[:n] = phi.T @ (m @ x[: rig.ndof])
        s[n : 2 * n] = (phi.T @ (m @ x[rig.ndof :])) / scale
        return s

    @staticmethod
    def _parameter(rig: FlexibleManipulator, p) -> Parameter:
        if isinstance(p, Parameter):
            one_of(p.name, "free", RIG_PARAMETERS)
            return p
        if not isinstance(p, str):
            raise TypeError(
                f"`free` holds field names or Parameters; got {type(p).__name__}"
            )
        return default_parameter(rig, p)

    # -- the rig at a parameter vector ------------------------------------------

    def rig_at(self, values) -> FlexibleManipulator:
        """The rig with the parameters at `values` (every parameter of this
        structure, in order); a ValueError when they make no rig."""
        fields, derived = {}, {}
        fields_of = self.parameters[: self._n_fields]
        values = np.asarray(values, dtype=float)[: self._n_fields]
        for p, v in zip(fields_of, values, strict=True):
            if p.name != DELAY:  # the record's, not the rig's
                (derived if p.name in _DERIVED else fields)[p.name] = float(v)
        rig = dataclasses.replace(self.rig, **fields)
        if "flexural_rigidity" in derived:
            second_moment = rig.width * rig.thickness**3 / 12.0
            derived["youngs_modulus"] = derived.pop("flexural_rigidity") / second_moment
        if "mass_per_length" in derived:
            derived["density"] = derived.pop("mass_per_length") / rig.area
        return dataclasses.replace(rig, **derived) if derived else rig

    def matrices(self, values, ts: float = 1.0) -> tuple[np.ndarray, ...]:
        """``(A, B, C, D)`` of the linear rig at `values` (friction and the
        torque limit left out) for the output, with its anti-aliasing filter
        for a sample time `ts` (the filter's cut-off is a share of the
        Nyquist frequency)."""
        s = self._sim_sensors
        a, b, c, d, _ = _continuous(
            self.rig_at(values),
            float(ts),
            s.antialias_order,
            s.antialias_cutoff,
            s.deflection_at,
            s.acceleration_at,
            self.n_modes,
        )
        rows = self._rows
        k = self.gain_at(values)
        return a, b[:, None], k * c[rows], k * d[rows][:, None]

    def discretise(self, values, ts: float) -> tuple[np.ndarray, ...]:
        """The linear rig's exact zero-order hold ``(Ad, Bd, C, D)`` at
        sample time `ts` for the output; with an input delay, the proper
        model of the delayed held input (its past inputs as states after
        the rig's, see :func:`spiralid.fms._zoh.delayed_system`)."""
        delay = self.delay_at(values)
        if delay is not None:
            ad, g0, g1, c, d = self._delayed(values, float(ts))
            return delayed_system(ad, g0, g1, c, d[:, 0], delay, float(ts))
        s = self._sim_sensors
        ad, bd, c, d, _ = _discrete(
            self.rig_at(values),
            float(ts),
            s.antialias_order,
            s.antialias_cutoff,
            s.deflection_at,
            s.acceleration_at,
            self.n_modes,
        )
        rows = self._rows
        k = self.gain_at(values)
        return (
            np.array(ad),
            np.array(bd)[:, None],
            k * np.array(c[rows]),
            k * np.array(d[rows])[:, None],
        )

    def _delayed(self, values, ts: float) -> tuple[np.ndarray, ...]:
        """``(Ad, G0, G1, C, D)`` of the rig with its input delayed
        (:func:`spiralid.fms._zoh.discretise_delayed`)."""
        a, b, c, d = self.matrices(values, ts)
        ad, g0, g1 = discretise_delayed(a, b[:, 0], ts, self.delay_at(values))
        return ad, g0, g1, c, d

    def simulate(self, values, u, ts: float) -> np.ndarray:
        """The output, shape (N,) (one sensor) or (N, p), over the torque
        `u` from rest, by the rig's own sampled simulation (from another
        initial state, by the exact zero-order hold of the same matrices),
        times the output gain; NaN when the values make no rig or the run
        leaves the floating-point range (the fit's penalty)."""
        uu = np.asarray(u, dtype=float).reshape(len(u), -1)
        if uu.shape[1] != 1:
            raise ValueError(f"`u` must have 1 input column; got {uu.shape[1]}")
        shape = (uu.shape[0],) if self.n_outputs == 1 else (uu.shape[0], self.n_outputs)
        nan = np.full(shape, np.nan)
        try:
            rig = self.rig_at(values)
        except (TypeError, ValueError):
            return nan
        if self._delay_at is not None:
            return self._from_delayed(values, uu, float(ts), nan)
        if self.state_parameters or self._x0_given.any():
            return self._from_state(values, uu, float(ts), nan)
        with np.errstate(all="ignore"):
            try:
                y, _, _ = rig._outputs(
                    uu[:, 0],
                    np.zeros(2 * rig.ndof),
                    float(ts),
                    self._sim_sensors,
                    False,
                    self.n_modes,
                )
            except (ValueError, np.linalg.LinAlgError):
                return nan
        y = self.gain_at(values) * np.asarray(y[:, self._rows], dtype=float)
        return y[:, 0] if self.n_outputs == 1 else y

    def _from_state(self, values, uu, ts: float, nan) -> np.ndarray:
        """The linear rig's run from the initial state at `values`: its
        exact zero-order hold (the matrices the rig's own run uses)."""
        with np.errstate(all="ignore"):
            try:
                ad, bd, c, d = self.discretise(values, ts)
            except (ValueError, np.linalg.LinAlgError):
                return nan
            x0 = self.initial_state(values)
            y = lti_run(ad, bd, c, d, x0, np.ascontiguousarray(uu))
        return y[:, 0] if self.n_outputs == 1 else y

    def _from_delayed(self, values, uu, ts: float, nan) -> np.ndarray:
        """The linear rig's run with its input delayed, from the initial
        state at `values` (the inputs before the record zero): the
        recursion of :func:`spiralid.fms._zoh.discretise_delayed` on the
        two shifted input columns."""
        delay = self.delay_at(values)
        with np.errstate(all="ignore"):
            try:
                ad, g0, g1, c, d = self._delayed(values, ts)
                shifted = delayed_inputs(uu[:, 0], delay, ts)
            except (ValueError, np.linalg.LinAlgError):
                return nan
            # The output's feedthrough sees u[n-k] on a whole delay, else
            # u[n-k-1] (the delayed input at the sampling instant).
            whole = delay_split(delay, ts)[1] == 0.0
            dd = np.hstack([d, np.zeros_like(d)] if whole else [np.zeros_like(d), d])
            bd = np.column_stack([g0, g1])
            y = lti_run(ad, bd, c, dd, self.initial_state(values), shifted)
        return y[:, 0] if self.n_outputs == 1 else y

    # -- the modes beside the FEM's ----------------------------------------------

    def modes_beside(self, values, n: int = 4) -> str:
        """A table of the first `n` flexible modes (Hz) of the rig at
        `values` beside those of `rig` (the finite-element model at its
        preset), with the fitted damping ratio of each
        (:meth:`~spiralid.fms.FlexibleManipulator.mode_damping`).

        Parameters
        ----------
        values : array_like
            Every parameter's value, in order.
        n : int, default 4
            Modes listed (fewer where the rig has fewer, ``2 n_elements``).

        Returns
        -------
        str
        """
        n = min(integer(n, "n", 1), 2 * self.rig.n_elements)
        fitted = self.rig_at(values)
        zeta = fitted.mode_damping(n)
        rows = ["mode  FEM preset Hz  fitted Hz  fitted damping"]
        for k, (f0, f1) in enumerate(
            zip(self.rig.modes(n), fitted.modes(n), strict=True), 1
        ):
            rows.append(f"{k:>4}  {f0:13.2f}  {f1:9.2f}  {zeta[k - 1]:14.4f}")
        return "\n".join(rows)

    # -- text and JSON ----------------------------------------------------------

    def output_source(self) -> str:
        """What gives the outputs, for messages: the sensors named."""
        return f"`output` {self.output!r}"

    def function_paths(self) -> dict[str, str]:
        """None: the rig's simulation is this class's own (model.json names
        the class)."""
        return {}

    def to_dict(self) -> dict:
        """The JSON form: this class's import path, the held rig, the
        parameters, the output, the truncation and the sensors."""
        return {
            "class": f"{type(self).__module__}:{type(self).__qualname__}",
            "kind": self.kind,
            "rig": dataclasses.asdict(self.rig),
            "parameters": [p.to_dict() for p in self.parameters[: self._n_fields]],
            "output_gain": (
                self.output_gain.to_dict()
                if isinstance(self.output_gain, Parameter)
                else self.output_gain
            ),
            "x0": self._x0_entries(),
            "output": self.output
            if isinstance(self.output, str)
            else list(self.output),
            "n_modes": self.n_modes,
            "sensors": dataclasses.asdict(self.sensors),
        }

    @classmethod
    def from_dict(cls, d: dict) -> RigGreyBox:
        """The structure :meth:`to_dict` wrote."""
        sensors = {
            k: tuple(v) if isinstance(v, list) else v for k, v in d["sensors"].items()
        }
        gain = d.get("output_gain", 1.0)
        x0 = d.get("x0")
        if x0 is not None:
            x0 = [Parameter(**e) if isinstance(e, dict) else e for e in x0]
        return cls(
            [Parameter(**p) for p in d["parameters"]],
            FlexibleManipulator(**d["rig"]),
            output=d["output"] if isinstance(d["output"], str) else tuple(d["output"]),
            n_modes=d.get("n_modes"),
            sensors=Sensors(**sensors),
            output_gain=Parameter(**gain) if isinstance(gain, dict) else gain,
            x0=x0,
        )

    def __repr__(self) -> str:
        modes = "all" if self.n_modes is None else self.n_modes
        return (
            f"RigGreyBox({self.kind}, {', '.join(self.outputs)}, modes {modes}; "
            f"{', '.join(self.names)})"
        )

    __str__ = __repr__
