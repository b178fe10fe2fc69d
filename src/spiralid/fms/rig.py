"""The single-link flexible manipulator rig: modes and sampled simulation.

Default constants are those of the University of Sheffield rig used in the
paper (its reference [13]), from the literature on that rig
(A. K. M. Azad, PhD thesis, University of Sheffield, 1994; M. O. Tokhi and
A. K. M. Azad (eds.), "Flexible Robot Manipulators", IET, 2008): an aluminium
beam of 900 x 19.008 x 3.2004 mm, E = 71 GPa, rho = 2710 kg/m^3, hub inertia
5.86e-4 kg m^2, no payload.  The modal damping ratio (0.02) is our choice: the
paper gives none, and "a few percent" is typical of such a link.

With these constants the model's first flexible modes are 13.3, 35.1, 64.8,
116.0 and 188.2 Hz (10 elements); the paper measured resonances at 11.72,
39.06 and 66.41 Hz with an FFT resolution of about 3.9 Hz.  The constants are
not tuned to close that gap.

Nonlinearities of the real rig (hub Coulomb and Stribeck friction, amplifier
torque saturation) are options that default to off, so the linear rig's
records are unchanged; :func:`nonlinear_rig` turns them on with the values
documented there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property, lru_cache

import numpy as np
from scipy.linalg import eigh
from scipy.optimize import brentq

from spiralid._checks import (
    generator,
    integer,
    nonneg,
    one_of,
    positive,
    real,
    real_array,
)
from spiralid.fms._zoh import discretise_zoh, simulate_discrete
from spiralid.fms.beam import _hermite, assemble
from spiralid.fms.sensors import Sensors, butterworth_ss, quantise

__all__ = ["FlexibleManipulator", "Recording", "nonlinear_rig"]

_OUTPUTS = ("hub_angle", "hub_velocity", "end_acceleration", "tip_deflection")
#: Each damping field's share of a flexible mode's damping ratio at its
#: frequency ``w`` (rad/s): the ratio is the fields' sum weighted by these
#: (the one ``damping_ratio``, then Rayleigh's ``alpha M + beta K``).
DAMPING_SHARES = {
    "damping_ratio": lambda w: np.ones_like(w),
    "mass_damping": lambda w: 1.0 / (2.0 * w),
    "stiffness_damping": lambda w: w / 2.0,
}
# The rig's inputs: the hub torque, and a shaker's force on the beam.
_INPUTS = ("torque", "force")
_INPUT_UNITS = {"torque": "N m", "force": "N"}
_UNITS = {
    "hub_angle": "rad",
    "hub_velocity": "rad/s",
    "end_acceleration": "m/s^2",
    "tip_deflection": "m",
}


@dataclass(frozen=True)
class Recording:
    """Sampled signals of one experiment on the rig.

    Sample ``k`` is taken at ``t[k] = k ts``, the instant the torque ``u[k]``
    starts to be applied (it is held until ``t[k+1]``): states are those
    reached under ``u[0..k-1]``, and an output with direct feedthrough (the
    end-point acceleration without anti-aliasing filter) includes ``D u[k]``,
    the right-hand side of the step, as in ``y = C x + D u``.

    Attributes
    ----------
    t : ndarray
        Sample instants (s).
    u : ndarray
        Hub torque (N m).
    hub_angle : ndarray
        Hub angle as the encoder reports it (rad).
    hub_velocity : ndarray
        Hub angular velocity as the tachometer reports it (rad/s).
    end_acceleration : ndarray
        End-point acceleration as the accelerometer reports it (m/s^2):
        ``L theta'' + w''(L)``.
    tip_deflection : ndarray
        Exact tip deflection ``w(L)`` relative to the hub frame (m); not a
        measured channel.
    ts : float
        Sample time (s).
    state : ndarray or None
        With ``return_state=True``: the exact ``(q, q')`` in the rig's
        generalised coordinates at each sample, shape ``(N, 2 ndof)``.
    deflection_at : tuple of float
        Positions of the deflection sensors along the beam, fractions of its
        length (:attr:`Sensors.deflection_at`); empty by default.
    deflection : ndarray or None
        Their exact deflections ``w(x)`` relative to the hub frame (m), shape
        ``(N, len(deflection_at))``; None without deflection sensors.  Column
        ``j`` is the output ``deflection_<x_j>`` of :meth:`iodata`.
    acceleration_at : tuple of float
        Positions of the further accelerometers
        (:attr:`Sensors.acceleration_at`); empty by default.
    acceleration : ndarray or None
        Their accelerations ``x theta'' + w''(x)`` as the accelerometers
        report them (m/s^2), shape ``(N, len(acceleration_at))``; None
        without them.  Column ``j`` is the output ``acceleration_<x_j>``.
    force : ndarray or None
        A shaker's force (N), the second input, when the experiment had one
        (:meth:`FlexibleManipulator.simulate`'s `force`); None otherwise.
    force_at : float or None
        Where it acted, a fraction of the length.
    """

    t: np.ndarray
    u: np.ndarray
    hub_angle: np.ndarray
    hub_velocity: np.ndarray
    end_acceleration: np.ndarray
    tip_deflection: np.ndarray
    ts: float
    state: np.ndarray | None = None
    deflection_at: tuple[float, ...] = ()
    deflection: np.ndarray | None = None
    acceleration_at: tuple[float, ...] = ()
    acceleration: np.ndarray | None = None
    force: np.ndarray | None = None
    force_at: float | None = None

    @property
    def input_names(self) -> tuple[str, ...]:
        """The inputs :meth:`iodata` takes: ``"torque"``, and ``"force"``
        when a shaker drove the beam too."""
        return _INPUTS if self.force is not None else _INPUTS[:1]

    @property
    def output_names(self) -> tuple[str, ...]:
        """Every output :meth:`iodata` takes: the four channels, then one
        ``deflection_<x>`` per deflection sensor and one
        ``acceleration_<x>`` per further accelerometer."""
        sensors = Sensors(
            deflection_at=self.deflection_at, acceleration_at=self.acceleration_at
        )
        return _OUTPUTS + sensors.positional_names

    def _output(self, name: str) -> np.ndarray:
        if name in _OUTPUTS:
            return getattr(self, name)
        k = self.output_names.index(name) - len(_OUTPUTS)
        if k < len(self.deflection_at):
            return self.deflection[:, k]
        return self.acceleration[:, k - len(self.deflection_at)]

    def iodata(
        self, name: str | list[str] = "end_acceleration", input: str | list = "torque"
    ):
        """The torque (or the shaker's force) and one output channel, or
        several, as a :class:`spiralid.IOData`.

        `name` is one of the recorded outputs (``"hub_angle"``,
        ``"hub_velocity"``, ``"end_acceleration"``, ``"tip_deflection"``, and
        ``"deflection_<x>"`` for each deflection sensor, see
        :attr:`output_names`), or a list of them: a record of several
        outputs that share the torque (``y`` of shape (N, p), each output
        with its own name and unit). `input` is one of
        :attr:`input_names`: ``"torque"`` (N m), or ``"force"`` (N) of a
        record with a shaker, whose outputs respond to both (an IOData of
        one input holds the other's response as disturbance), or a list of
        them: a record of several inputs (``u`` of shape (N, m)).

        ``spiralid.sysid.data`` is imported here, inside the method: it is the
        one sanctioned dependency of ``fms`` on the rest of the package, kept
        local so that ``fms`` itself imports nothing of ours.

        Examples
        --------
        >>> from spiralid.fms import FlexibleManipulator, bang_bang
        >>> u = bang_bang(0.3, 0.05, 0.1, 1.0, 500.0)
        >>> rec = FlexibleManipulator().simulate(u)
        >>> d = rec.iodata("end_acceleration")
        >>> d.n, d.ts, d.output_name, d.output_unit
        (500, 0.002, 'end_acceleration', 'm/s^2')
        >>> rec.iodata(["hub_angle", "tip_deflection"]).output_units
        ('rad', 'm')
        """
        from spiralid.sysid.data import IOData

        inputs = list(input) if isinstance(input, list | tuple) else [input]
        for one in inputs:
            one_of(one, "input", self.input_names)
        if not inputs or len(set(inputs)) != len(inputs):
            raise ValueError(f"`input` must list each input once; got {input!r}")
        names = list(name) if isinstance(name, list | tuple) else [name]
        known = self.output_names
        for one in names:
            one_of(one, "name", known)
        if not names or len(set(names)) != len(names):
            raise ValueError(f"`name` must list each output once; got {name!r}")
        several = len(names) > 1
        y = [self._output(one) for one in names]
        u = [self.u if one == "torque" else self.force for one in inputs]
        driven = len(inputs) > 1
        return IOData(
            np.column_stack(u) if driven else u[0],
            np.column_stack(y) if several else y[0],
            ts=self.ts,
            input_name=tuple(inputs) if driven else inputs[0],
            output_name=tuple(names) if several else names[0],
            input_unit=tuple(_INPUT_UNITS[one] for one in inputs)
            if driven
            else _INPUT_UNITS[inputs[0]],
            output_unit=tuple(_unit(one) for one in names)
            if several
            else _unit(names[0]),
        )


def _unit(name: str) -> str:
    if name in _UNITS:
        return _UNITS[name]
    return "m/s^2" if name.startswith("acceleration_") else "m"


@dataclass(frozen=True, kw_only=True)
class FlexibleManipulator:
    """Hub-beam-payload finite-element model of the Sheffield rig.

    A rigid hub turning in the horizontal plane drives an aluminium
    Euler-Bernoulli beam clamped to it, with an optional tip payload.  The
    beam is split into ``n_elements`` Hermite cubic elements with consistent
    mass; the hub angle is the first generalised coordinate (see
    :mod:`spiralid.fms.beam`).

    Parameters
    ----------
    length : float
        Beam length L (m).  Default 0.9 (Azad 1994).
    width, thickness : float
        Beam cross-section (m).  Defaults 19.008e-3 and 3.2004e-3 (Azad 1994).
    youngs_modulus : float
        E (Pa).  Default 71e9 (aluminium; Azad 1994).
    density : float
        rho (kg/m^3).  Default 2710 (aluminium; Azad 1994).
    hub_inertia : float
        I_h (kg m^2), > 0.  Default 5.86e-4 (Azad 1994).
    payload_mass : float
        Tip point mass m_p (kg).  Default 0 (the paper's experiments).
    payload_inertia : float
        Tip payload's own moment of inertia (kg m^2).  Default 0.
    damping_ratio : float
        Modal damping ratio of every flexible mode, in [0, 1).  Default 0.02
        (our choice: "a few percent").  The rigid mode is never damped by it.
    hub_friction : float
        Viscous friction at the hub (N m s/rad).  Default 0.
    n_elements : int
        Number of beam elements, >= 1.  Default 10.
    coulomb_friction : float
        Coulomb (sliding) friction torque at the hub (N m), >= 0.  Default 0
        (off).
    static_friction : float
        Breakaway torque at the hub (N m), >= 0.  When it exceeds
        `coulomb_friction` the friction follows the Stribeck law
        ``Fc + (Fs - Fc) exp(-(v / v_s)^2)``.  Default 0 (off).
    stribeck_velocity : float
        ``v_s`` of the Stribeck law (rad/s), > 0.  Default 0.1.
    torque_limit : float or None
        The amplifier's saturation: the applied torque is
        ``clip(u, -limit, limit)`` (N m, > 0).  Default None (no limit).
    friction_substeps : int
        Sub-steps per sample of the friction's time stepping (see
        :mod:`spiralid.fms._friction`), >= 1.  Default 20.  Only used when
        a friction torque is on.
    mass_damping : float
        Rayleigh damping's mass-proportional coefficient alpha (1/s), >= 0:
        adds ``alpha / (2 w_k)`` to flexible mode k's damping ratio.
        Default 0.
    stiffness_damping : float
        Rayleigh damping's stiffness-proportional coefficient beta (s),
        >= 0: adds ``beta w_k / 2`` to flexible mode k's damping ratio (a
        material's internal damping, growing with frequency).  Default 0.
        With `mass_damping`, the flexible modes are damped as by ``C =
        alpha M + beta K`` (see :meth:`mode_damping`); the rigid mode's
        share of ``alpha M`` (a damping to the ground, which no hub-driven
        arm has) is left out, as `damping_ratio`'s is.

    Examples
    --------
    >>> rig = FlexibleManipulator()
    >>> np.round(rig.modes(3), 1)
    array([13.3, 35.1, 64.8])
    """

    length: float = 0.9
    width: float = 19.008e-3
    thickness: float = 3.2004e-3
    youngs_modulus: float = 71e9
    density: float = 2710.0
    hub_inertia: float = 5.86e-4
    payload_mass: float = 0.0
    payload_inertia: float = 0.0
    damping_ratio: float = 0.02
    hub_friction: float = 0.0
    n_elements: int = 10
    coulomb_friction: float = 0.0
    static_friction: float = 0.0
    stribeck_velocity: float = 0.1
    torque_limit: float | None = None
    friction_substeps: int = 20
    # Last, so that the fields before keep their positions.
    mass_damping: float = 0.0
    stiffness_damping: float = 0.0

    def __post_init__(self) -> None:
        for name in (
            "length",
            "width",
            "thickness",
            "youngs_modulus",
            "density",
            "hub_inertia",
        ):
            object.__setattr__(self, name, positive(getattr(self, name), name))
        for name in (
            "payload_mass",
            "payload_inertia",
            "mass_damping",
            "stiffness_damping",
            "hub_friction",
            "coulomb_friction",
            "static_friction",
        ):
            object.__setattr__(self, name, nonneg(getattr(self, name), name))
        object.__setattr__(
            self,
            "stribeck_velocity",
            positive(self.stribeck_velocity, "stribeck_velocity"),
        )
        if self.torque_limit is not None:
            object.__setattr__(
                self, "torque_limit", positive(self.torque_limit, "torque_limit")
            )
        object.__setattr__(
            self,
            "friction_substeps",
            integer(self.friction_substeps, "friction_substeps", 1),
        )
        what = f"`damping_ratio` must be in [0, 1); got {self.damping_ratio!r}"
        try:
            z = nonneg(self.damping_ratio, "damping_ratio")
        except TypeError:
            raise TypeError(what) from None
        except ValueError:
            z = math.nan
        if not z < 1.0:
            raise ValueError(what)
        object.__setattr__(self, "damping_ratio", z)
        object.__setattr__(
            self, "n_elements", integer(self.n_elements, "n_elements", 1)
        )

    # ------------------------------------------------------------ properties
    @property
    def ndof(self) -> int:
        """Number of generalised coordinates, ``2 n_elements + 1``."""
        return 2 * self.n_elements + 1

    @property
    def has_friction(self) -> bool:
        """Whether a Coulomb or Stribeck friction torque acts at the hub."""
        return self.coulomb_friction > 0.0 or self.static_friction > 0.0

    @property
    def area(self) -> float:
        """Cross-section area A (m^2)."""
        return self.width * self.thickness

    @property
    def flexural_rigidity(self) -> float:
        """E I (N m^2), I = width thickness^3 / 12."""
        return self.youngs_modulus * self.width * self.thickness**3 / 12.0

    @property
    def total_inertia(self) -> float:
        """Rigid-body inertia about the hub: I_h + rho A L^3 / 3 + m_p L^2 + J_p."""
        return float(self.mass_matrix[0, 0])

    @cached_property
    def _mass_and_stiffness(self) -> tuple[np.ndarray, np.ndarray]:
        M, K = assemble(
            self.n_elements,
            self.length,
            self.flexural_rigidity,
            self.density * self.area,
            self.hub_inertia,
            self.payload_mass,
            self.payload_inertia,
        )
        M.flags.writeable = False
        K.flags.writeable = False
        return M, K

    @property
    def mass_matrix(self) -> np.ndarray:
        """Consistent mass matrix (read-only), coordinates as in ``beam``."""
        return self._mass_and_stiffness[0]

    @property
    def stiffness_matrix(self) -> np.ndarray:
        """Stiffness matrix (read-only); zero row/column for the hub angle."""
        return self._mass_and_stiffness[1]

    @cached_property
    def _modal(self) -> tuple[np.ndarray, np.ndarray]:
        """Natural frequencies (rad/s, rigid first) and mass-normalised modes.

        The rigid mode is exactly ``e_theta / sqrt(J)``; the flexible modes
        are found on the complement that is mass-orthogonal to it (eliminate
        ``theta'' = -m_tw w'' / J`` from the hub row, leaving the Schur
        complement mass ``M_ww - m_tw m_tw^T / J``), so no eigenvalue has to
        be recognised as a numerical zero.
        """
        M, K = self._mass_and_stiffness
        J = M[0, 0]
        mtw = M[0, 1:]
        meff = M[1:, 1:] - np.outer(mtw, mtw) / J
        lam, v = eigh(K[1:, 1:], meff)
        n = self.ndof
        phi = np.zeros((n, n))
        phi[0, 0] = 1.0 / math.sqrt(J)
        phi[1:, 1:] = v
        phi[0, 1:] = -(mtw @ v) / J
        omega = np.concatenate([[0.0], np.sqrt(lam)])
        return omega, phi

    def _modal_damping(self, omega: np.ndarray) -> np.ndarray:
        """``2 zeta_k w_k`` of each mode at the frequencies `omega` (rad/s,
        the rigid mode's 0 first): zero for the rigid mode, whose frequency
        the mass damping's share would divide by."""
        out = np.zeros_like(omega)
        flexible = omega[1:]
        zeta = sum(
            getattr(self, name) * share(flexible)
            for name, share in DAMPING_SHARES.items()
        )
        out[1:] = 2.0 * flexible * zeta
        return out

    def mode_damping(self, n: int | None = None) -> np.ndarray:
        """Damping ratio of each flexible mode, ascending in frequency:
        ``damping_ratio + mass_damping / (2 w_k) + stiffness_damping w_k /
        2``.

        Parameters
        ----------
        n : int, optional
            Return only the first ``n`` (at most ``2 n_elements``); default
            all ``2 n_elements``.

        Returns
        -------
        ndarray

        Examples
        --------
        >>> rig = FlexibleManipulator(damping_ratio=0.0, stiffness_damping=1e-4)
        >>> np.round(rig.mode_damping(2), 4)  # beta w_k / 2
        array([0.0042, 0.011 ])
        """
        w = 2.0 * math.pi * self.modes(n)
        return sum(
            getattr(self, name) * share(w) for name, share in DAMPING_SHARES.items()
        )

    @property
    def damping_matrix(self) -> np.ndarray:
        """Damping matrix: modal damping of the flexible modes plus hub friction.

        ``C = M Phi diag(2 zeta_i w_i) Phi^T M + c_h e_theta e_theta^T`` with
        the rigid mode's entry zero, so only friction damps the rigid motion
        (``zeta_i`` of :meth:`mode_damping`).
        """
        omega, phi = self._modal
        mp = self.mass_matrix @ phi
        C = (mp * self._modal_damping(omega)) @ mp.T
        C[0, 0] += self.hub_friction
        return C

    # --------------------------------------------------------------- methods
    def modes(self, n: int | None = None) -> np.ndarray:
        """Undamped natural frequencies of the flexible modes (Hz), ascending.

        Parameters
        ----------
        n : int, optional
            Return only the first ``n`` (at most ``2 n_elements``); default
            all ``2 n_elements``.

        Examples
        --------
        >>> FlexibleManipulator(n_elements=20).modes(2).round(2)
        array([13.31, 35.11])
        """
        f = self._modal[0][1:] / (2.0 * math.pi)
        if n is None:
            return f
        n = integer(n, "n", 1)
        if n > f.size:
            # Fewer frequencies than asked for would go unnoticed downstream.
            raise ValueError(
                f"`n` must be at most 2 n_elements = {f.size} (the model's "
                f"flexible modes); got {n!r}"
            )
        return f[:n]

    def deflection_rows(self, positions) -> np.ndarray:
        """Rows ``r`` with ``w(x L) = r @ q``: the beam's deflection relative
        to the hub frame at fractions ``x`` of its length, from the
        generalised coordinates ``q`` (the Hermite shape functions of the
        element that holds the point).

        Parameters
        ----------
        positions : array_like of float
            Fractions of the length from the hub, each in [0, 1].

        Returns
        -------
        ndarray, shape (len(positions), ndof)

        Examples
        --------
        >>> rig = FlexibleManipulator(n_elements=4)
        >>> rig.deflection_rows([1.0])[0, rig.ndof - 2]   # the tip node's w
        np.float64(1.0)
        """
        x = real_array(positions, "positions").ravel()
        if not np.all((x >= 0.0) & (x <= 1.0)):
            raise ValueError(
                "`positions` must be fractions of the length in [0, 1]; got "
                f"{positions!r}"
            )
        n = self.n_elements
        le = self.length / n
        element = np.minimum(np.floor(x * n).astype(int), n - 1)
        xi = x * n - element
        shape = _hermite(xi, le).T  # (k, 4): w_e, w_e', w_e+1, w_e+1'
        rows = np.zeros((x.size, self.ndof))
        for k, e in enumerate(element):
            # Node j >= 1 has w_j at q[2j - 1] and w_j' at q[2j]; node 0 is
            # clamped (no coordinates).
            first = 0 if e == 0 else 2 * e - 1
            cols = np.arange(first, 2 * e + 3)
            rows[k, cols] = shape[k, 4 - cols.size :]
        return rows

    def load_vector(self, position: float) -> np.ndarray:
        """The generalised force of a unit point force at a point of the
        beam: the consistent load vector of a shaker.

        The force (1 N) acts at the fraction `position` of the length, in
        the plane of motion, perpendicular to the undeformed beam, and is
        fixed in space (a shaker's stinger), so it does the virtual work
        ``delta W = x L delta theta + w(x L)`` of the point's displacement
        in the inertial frame (:meth:`mode_shape`'s ``"inertial"``): the
        hub angle's entry is its moment ``x L`` about the axis, and the
        nodal entries are the Hermite shape functions of the element that
        holds the point (:meth:`deflection_rows`), the consistent loads.

        Parameters
        ----------
        position : float
            Fraction of the length from the hub, in (0, 1].

        Returns
        -------
        ndarray, shape (ndof,)

        Examples
        --------
        At a node the load is that node's deflection alone, plus its moment
        about the hub:

        >>> rig = FlexibleManipulator(n_elements=4, length=1.0)
        >>> rig.load_vector(0.5).round(12).tolist()
        [0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        """
        x = _position(position, "position")
        load = self.deflection_rows([x])[0]
        load[0] += x * self.length
        return load

    def mode_shape(self, mode: int, positions, *, frame: str = "hub") -> np.ndarray:
        """The deflection of a flexible mode along the beam, scaled so that
        its largest magnitude on the beam is 1.

        Parameters
        ----------
        mode : int
            The flexible mode, 1 for the first (lowest frequency).
        positions : array_like of float
            Fractions of the length from the hub, each in [0, 1].
        frame : {"hub", "inertial"}
            ``"hub"``: the deflection ``w(x)`` relative to the hub frame (what
            ``tip_deflection`` and ``deflection_<x>`` record). ``"inertial"``:
            the displacement ``x theta + w(x)`` (what an accelerometer at
            ``x`` sees, as ``end_acceleration`` at the tip).

        Returns
        -------
        ndarray, shape (len(positions),)
            The shape; its sign is that of its largest-magnitude value on a
            grid of 64 points per element, taken as positive.

        Examples
        --------
        >>> rig = FlexibleManipulator()
        >>> float(abs(rig.mode_shape(2, [rig.mode_nodes(2)[0]])[0])) < 1e-9
        True
        """
        f = self._shape(mode, frame)
        grid = np.linspace(0.0, 1.0, 64 * self.n_elements + 1)
        on_grid = f(grid)
        scale = on_grid[np.argmax(np.abs(on_grid))]
        return f(real_array(positions, "positions").ravel()) / scale

    def mode_nodes(self, mode: int, *, frame: str = "hub") -> np.ndarray:
        """Where a flexible mode's deflection changes sign along the beam.

        The sign changes on a grid of 64 points per element, each refined
        to a root of the finite-element interpolant (Brent's method); the
        clamp at the hub, where the deflection is zero in every mode, is
        not counted.

        Parameters
        ----------
        mode : int
            The flexible mode, 1 for the first.
        frame : {"hub", "inertial"}
            As for :meth:`mode_shape`.

        Returns
        -------
        ndarray
            The nodes as fractions of the length, ascending, in (0, 1].

        Examples
        --------
        An accelerometer at 0.832 of the default rig's length barely sees
        its second mode; in the hub frame that mode's only node is near the
        hub (the light hub turns back against the beam):

        >>> rig = FlexibleManipulator()
        >>> rig.mode_nodes(2, frame="inertial").round(3)
        array([0.348, 0.832])
        >>> rig.mode_nodes(2).round(3)
        array([0.056])
        """
        f = self._shape(mode, frame)
        grid = np.linspace(0.0, 1.0, 64 * self.n_elements + 1)[1:]
        v = f(grid)
        scale = float(np.max(np.abs(v)))
        nodes = [float(x) for x, w in zip(grid, v, strict=True) if w == 0.0]
        for i in np.flatnonzero(v[:-1] * v[1:] < 0.0):
            nodes.append(
                brentq(
                    lambda x: float(f(np.array([x]))[0]) / scale,
                    grid[i],
                    grid[i + 1],
                    xtol=1e-15,
                )
            )
        return np.array(sorted(nodes))

    def _shape(self, mode: int, frame: str):
        """Mode `mode`'s unscaled deflection as a function of positions."""
        mode = integer(mode, "mode", 1)
        if mode > 2 * self.n_elements:
            raise ValueError(
                f"`mode` must be at most 2 n_elements = {2 * self.n_elements}; "
                f"got {mode!r}"
            )
        if frame not in ("hub", "inertial"):
            raise ValueError(f"`frame` must be 'hub' or 'inertial'; got {frame!r}")
        phi = self._modal[1][:, mode]
        rigid = self.length * phi[0] if frame == "inertial" else 0.0

        def deflection(x: np.ndarray) -> np.ndarray:
            return self.deflection_rows(x) @ phi + rigid * x

        return deflection

    def _plant(
        self,
        deflection_at: tuple[float, ...] = (),
        acceleration_at: tuple[float, ...] = (),
        n_modes: int | None = None,
        force_at: float | None = None,
    ) -> tuple[np.ndarray, ...]:
        """Continuous model in modal coordinates, scaled for the exponential.

        State ``s = [eta, nu]`` with ``q = Phi eta`` and velocities
        ``nu_0 = eta_0'`` (rigid), ``nu_i = eta_i' / w_i`` (flexible), so
        every entry of ``A`` is of order ``w_i`` rather than ``w_i^2``.
        Returns ``A, B`` and output rows ``(C, D)`` for hub angle, hub
        velocity, end-point acceleration and tip deflection, then the
        deflection at each of `deflection_at` and the acceleration at each
        of `acceleration_at`, plus the velocity scaling. With `n_modes`, only
        the rigid mode and the first `n_modes` flexible ones are kept (a
        modal truncation: the grey box's reduced model). The input is the
        hub torque, or with `force_at` a point force there
        (:meth:`load_vector`): ``B`` and ``D`` are that input's.
        """
        omega, phi = self._modal
        if n_modes is not None:
            omega, phi = omega[: n_modes + 1], phi[:, : n_modes + 1]
        n = omega.size
        scale = omega.copy()
        scale[0] = 1.0
        g = phi[0]  # hub torque's modal participation
        # The input's participation: the torque's, or the force's load.
        gi = g if force_at is None else phi.T @ self.load_vector(force_at)
        cm = np.diag(self._modal_damping(omega)) + self.hub_friction * np.outer(g, g)
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.diag(scale)
        A[n:, :n] = -np.diag(omega**2 / scale)
        A[n:, n:] = -(cm * scale[None, :]) / scale[:, None]
        B = np.concatenate([np.zeros(n), gi / scale])
        tip = phi[self.ndof - 2]
        h = self.length * phi[0] + tip  # end point's share of each mode
        nd = len(deflection_at)
        C = np.zeros((4 + nd + len(acceleration_at), 2 * n))
        D = np.zeros(C.shape[0])
        C[0, :n] = g
        C[1, n:] = g * scale
        C[2, :n] = -h * omega**2
        C[2, n:] = -(h @ cm) * scale
        D[2] = h @ gi
        C[3, :n] = tip
        if deflection_at:
            C[4 : 4 + nd, :n] = self.deflection_rows(deflection_at) @ phi
        if acceleration_at:
            x = np.asarray(acceleration_at)
            # Each accelerometer's share of each mode, as h is the end point's.
            hx = np.outer(x, self.length * phi[0]) + self.deflection_rows(x) @ phi
            C[4 + nd :, :n] = -hx * omega**2
            C[4 + nd :, n:] = -(hx @ cm) * scale
            D[4 + nd :] = hx @ gi
        return A, B, C, D, scale

    def simulate(
        self,
        torque,
        fs: float = 500.0,
        rng=None,
        *,
        sensors: Sensors | None = None,
        x0=None,
        return_state: bool = False,
        force=None,
        force_at: float | None = None,
    ) -> Recording:
        """Drive the hub with a sampled torque held constant between samples,
        and optionally the beam with a shaker's force.

        The continuous model (plus the anti-aliasing filters) is discretised
        exactly for a zero-order hold, ``Ad = e^{A ts}``, ``Bd = int e^{As} ds
        B`` (one matrix exponential), and run in closed form: no numerical
        ODE integration.

        Parameters
        ----------
        torque : array_like, shape (N,) or (N, 1)
            Hub torque in N m at ``t = k / fs``, held for one sample.
        fs : float
            Sample rate in Hz, > 0.
        rng : None, int or numpy.random.Generator
            Seed of the sensor noise (only drawn when a noise std is > 0:
            tachometer first, then accelerometer).
        sensors : Sensors, optional
            Instrumentation; default ``Sensors()`` (2048-line x4 encoder, no
            noise, 4th-order Butterworth anti-aliasing at 0.35 x Nyquist on the
            tachometer and accelerometer).  ``Sensors.ideal()`` samples the
            exact signals.
        x0 : array_like, shape (2 ndof,), optional
            Initial ``(q, q')`` in generalised coordinates; default rest.
            Anti-aliasing filters start at rest.
        return_state : bool
            Also return the exact ``(q, q')`` at every sample.
        force : array_like, shape (N,), optional
            A second input: a shaker's force in N at ``t = k / fs``, held
            for one sample, as many samples as `torque`, acting at
            `force_at` (:meth:`load_vector`). Its response is added to the
            torque's (the linear rig's superposition); the torque limit
            does not clip it, and a rig with hub friction refuses it.
            Default none: the record is exactly as without this option.
        force_at : float, optional
            Where the force acts, a fraction of the length in (0, 1];
            required with `force`.

        Returns
        -------
        Recording

        Examples
        --------
        >>> from spiralid.fms import bang_bang
        >>> rig = FlexibleManipulator()
        >>> u = bang_bang(0.3, 0.1, 0.0, 4.0, 500.0)
        >>> rec = rig.simulate(u, sensors=Sensors.ideal())
        >>> round(float(rec.hub_angle[-1]) / (0.3 * 0.1**2 / rig.total_inertia), 2)
        1.0
        """
        fs_v = positive(fs, "fs")
        u = _torque(torque)
        if sensors is None:
            sensors = Sensors()
        elif not isinstance(sensors, Sensors):
            raise TypeError(f"`sensors` must be a Sensors or None; got {sensors!r}")
        x0v = _initial_state(x0, self.ndof)
        if not isinstance(return_state, bool | np.bool_):
            raise TypeError(
                f"`return_state` must be True or False; got {return_state!r}"
            )
        shaker = self._shaker(force, force_at, u.size)
        # Checked even without noise, so a bad seed never goes unnoticed.
        gen = generator(rng)
        ts = 1.0 / fs_v
        y, s, scale = self._outputs(u, x0v, ts, sensors, return_state)
        if shaker is not None:
            y, s = self._add_force(y, s, shaker, ts, sensors)
        if not np.all(np.isfinite(y)):
            # Only absurd inputs get here (a sample time of 1e300 s, torques
            # near the float limit): say so rather than return NaN.
            raise ValueError(
                "`torque` and `fs` drive the model beyond the float range "
                f"(non-finite samples); got fs={fs!r}, "
                f"max |torque|={float(np.max(np.abs(u))):g}"
            )
        state = None
        if s is not None:
            n, phi = self.ndof, self._modal[1]
            state = np.hstack([s[:, :n] @ phi.T, (s[:, n : 2 * n] * scale) @ phi.T])
        recording = _recording(u, y, ts, sensors, gen, state)
        if shaker is None:
            return recording
        return replace(recording, force=shaker[0].copy(), force_at=shaker[1])

    def _shaker(self, force, force_at, n: int) -> tuple[np.ndarray, float] | None:
        """`force` and `force_at` of :meth:`simulate` checked: None without
        a force, else the force as a 1-D array of `n` finite samples and
        its position."""
        if force is None:
            if force_at is not None:
                raise ValueError("`force_at` needs a `force` to place; got no force")
            return None
        if force_at is None:
            raise ValueError("`force` needs `force_at`, where along the beam it acts")
        if self.has_friction:
            raise ValueError(
                "`force` is simulated on the linear rig only (superposition); "
                "this rig has hub friction"
            )
        f = _torque(force, "force").copy()
        if f.size != n:
            raise ValueError(
                f"`force` must have as many samples as `torque` ({n}); got shape "
                f"{np.shape(force)}"
            )
        return f, _position(force_at, "force_at")

    def _add_force(self, y, s, shaker, ts: float, sensors: Sensors):
        """The outputs (and modal states) with the force's response, from
        rest, added: the rig is linear without friction."""
        force, at = shaker
        Ad, Bd, C, D, _ = _discrete(
            self,
            ts,
            sensors.antialias_order,
            sensors.antialias_cutoff,
            sensors.deflection_at,
            sensors.acceleration_at,
            force_at=at,
        )
        yf, sf = simulate_discrete(
            Ad, Bd, C, D, force, np.zeros(Ad.shape[0]), s is not None
        )
        return y + yf, (None if s is None else s + sf)

    def _outputs(
        self,
        u,
        x0v,
        ts: float,
        sensors: Sensors,
        return_state: bool,
        n_modes: int | None = None,
    ):
        """The exact sensor outputs (before noise and quantisation) for the
        torque `u` from the state `x0v`, the modal states when asked for
        (else None), and the velocity scale of the modal states; with
        `n_modes`, of the model truncated to that many flexible modes."""
        # With friction the run is sub-stepped (see spiralid.fms._friction):
        # only the sub-step's model is needed. The filters' cutoff is
        # relative to the Nyquist frequency: the same filter in Hz at the
        # sub-step's rate.
        m = self.friction_substeps if self.has_friction else 1
        Ad, Bd, C, D, scale = _discrete(
            self,
            ts / m if m > 1 else ts,
            sensors.antialias_order,
            sensors.antialias_cutoff / m if m > 1 else sensors.antialias_cutoff,
            sensors.deflection_at,
            sensors.acceleration_at,
            n_modes,
        )
        n, nq = scale.size, self.ndof
        phi = self._modal[1][:, :n]
        M = self.mass_matrix
        s0 = np.zeros(Ad.shape[0])
        s0[:n] = phi.T @ (M @ x0v[:nq])
        s0[n : 2 * n] = (phi.T @ (M @ x0v[nq:])) / scale
        if self.torque_limit is not None:
            u_applied = np.clip(u, -self.torque_limit, self.torque_limit)
        else:
            u_applied = u
        if self.has_friction:
            y, s = self._simulate_friction(u_applied, s0, (Ad, Bd, C, D), n_modes)
            return y, (s if return_state else None), scale
        y, s = simulate_discrete(Ad, Bd, C, D, u_applied, s0, return_state)
        return y, s, scale

    def _simulate_friction(self, u, s0, sub_model, n_modes: int | None = None):
        """Outputs and states with hub friction, sub-stepped (see
        :mod:`spiralid.fms._friction`); `sub_model` the exact ZOH ``(Ad,
        Bd, C, D)`` of one sub-step."""
        from spiralid.fms._friction import simulate_friction

        Ad, Bd, C, D = sub_model
        cv = np.zeros(Ad.shape[0])
        plant_c = self._plant(n_modes=n_modes)[2]
        cv[: plant_c.shape[1]] = plant_c[1]
        return simulate_friction(
            Ad,
            Bd,
            C,
            D,
            cv,
            u,
            s0,
            self.friction_substeps,
            self.coulomb_friction,
            self.static_friction,
            self.stribeck_velocity,
        )


def nonlinear_rig(**overrides) -> FlexibleManipulator:
    """The rig with its nonlinearities on: hub friction and torque saturation.

    Values (our choice, stated as such; no measured friction or amplifier
    limit of the Sheffield rig is in the sources this package cites):
    Coulomb friction 0.02 N m and breakaway torque 0.03 N m with a Stribeck
    velocity of 0.1 rad/s, i.e. 7-10 % of the paper's 0.3 N m pulses, the
    order reported for small DC servo drives with brushes and bearings; the
    amplifier saturates at 0.25 N m, so the paper's pulses and any larger
    torque are clipped.  Backlash is not modelled (the Sheffield rig drives
    the hub directly, without a gearbox).

    Parameters
    ----------
    **overrides
        Any other :class:`FlexibleManipulator` field, or one of these to
        change it.

    Returns
    -------
    FlexibleManipulator

    Examples
    --------
    >>> rig = nonlinear_rig()
    >>> rig.coulomb_friction, rig.static_friction, rig.torque_limit
    (0.02, 0.03, 0.25)
    """
    fields = {
        "coulomb_friction": 0.02,
        "static_friction": 0.03,
        "stribeck_velocity": 0.1,
        "torque_limit": 0.25,
    }
    fields.update(overrides)
    return FlexibleManipulator(**fields)


def _torque(torque, name: str = "torque") -> np.ndarray:
    """`torque` (or the input `name`) of :meth:`FlexibleManipulator.simulate`
    as a finite, non-empty 1-D float array (an (N, 1) column is flattened)."""
    u = real_array(torque, name)
    if u.ndim == 2 and u.shape[1] == 1:
        u = u[:, 0]
    if u.ndim != 1 or u.size == 0:
        raise ValueError(
            f"`{name}` must be a non-empty 1-D array or (N, 1); "
            f"got shape {np.shape(torque)}"
        )
    if not np.all(np.isfinite(u)):
        bad = int(np.flatnonzero(~np.isfinite(u))[0])
        raise ValueError(
            f"`{name}` must be finite; got {float(u[bad])!r} at index {bad}"
        )
    return u


def _position(value, name: str) -> float:
    """`value` as a fraction of the beam's length in (0, 1]."""
    what = f"`{name}` must be a fraction of the length in (0, 1]; got {value!r}"
    try:
        x = real(value, name)
    except TypeError:
        raise TypeError(what) from None
    except ValueError:
        x = math.nan
    if not 0.0 < x <= 1.0:
        raise ValueError(what)
    return x


def _initial_state(x0, n: int) -> np.ndarray:
    """`x0` of :meth:`FlexibleManipulator.simulate`: ``(q, q')`` of `n`
    generalised coordinates, rest when None."""
    if x0 is None:
        return np.zeros(2 * n)
    x0v = real_array(x0, "x0")
    if x0v.shape != (2 * n,) or not np.all(np.isfinite(x0v)):
        raise ValueError(
            f"`x0` must hold {2 * n} finite numbers (q, q'), shape "
            f"({2 * n},); got {x0!r:.80}"
        )
    return x0v


def _recording(u, y, ts: float, sensors: Sensors, gen, state) -> Recording:
    """The recording of the exact outputs `y`: the encoder's quantisation
    and the sensors' noise, drawn in a fixed order (tachometer,
    accelerometer, then the further accelerometers) so that adding a
    channel leaves the others' noise unchanged."""
    hub_velocity = y[:, 1]
    acc = y[:, 2]
    if sensors.tach_noise > 0.0:
        hub_velocity = hub_velocity + gen.normal(0.0, sensors.tach_noise, u.size)
    if sensors.accel_noise > 0.0:
        acc = acc + gen.normal(0.0, sensors.accel_noise, u.size)
    nd = len(sensors.deflection_at)
    further = y[:, 4 + nd :].copy() if sensors.acceleration_at else None
    if further is not None and sensors.accel_noise > 0.0:
        further += gen.normal(0.0, sensors.accel_noise, further.shape[::-1]).T
    return Recording(
        t=np.arange(u.size) * ts,
        u=u.copy(),
        hub_angle=quantise(y[:, 0], sensors.encoder_resolution),
        hub_velocity=hub_velocity,
        end_acceleration=acc,
        tip_deflection=y[:, 3].copy(),
        ts=ts,
        state=state,
        deflection_at=sensors.deflection_at,
        deflection=y[:, 4 : 4 + nd].copy() if nd else None,
        acceleration_at=sensors.acceleration_at,
        acceleration=further,
    )


@lru_cache(maxsize=16)
def _discrete(
    rig: FlexibleManipulator,
    ts: float,
    order: int,
    cutoff: float,
    deflection_at: tuple[float, ...] = (),
    acceleration_at: tuple[float, ...] = (),
    n_modes: int | None = None,
    force_at: float | None = None,
) -> tuple[np.ndarray, ...]:
    """Exact ZOH model of the rig plus anti-aliasing filters (cached); the
    sensors along the beam are outputs after the four channels; the input
    is the hub torque, or a point force at `force_at`."""
    A, B, C, D, scale = _continuous(
        rig, ts, order, cutoff, deflection_at, acceleration_at, n_modes, force_at
    )
    Ad, Bd = discretise_zoh(A, B, ts)
    for arr in (Ad, Bd, C, D, scale):
        arr.flags.writeable = False
    return Ad, Bd, C, D, scale


def _continuous(
    rig: FlexibleManipulator,
    ts: float,
    order: int,
    cutoff: float,
    deflection_at: tuple[float, ...] = (),
    acceleration_at: tuple[float, ...] = (),
    n_modes: int | None = None,
    force_at: float | None = None,
) -> tuple[np.ndarray, ...]:
    """The continuous model :func:`_discrete` samples: the rig's plant
    (`n_modes` flexible modes, all by default; the input a point force at
    `force_at`, or the hub torque) with an anti-aliasing filter of `order`
    in front of each analogue channel (`cutoff` a fraction of the Nyquist
    frequency of `ts`)."""
    A, B, C, D, scale = rig._plant(deflection_at, acceleration_at, n_modes, force_at)
    if order > 0:
        af, bf, cf = butterworth_ss(order, cutoff * 0.5 / ts)
        npl = A.shape[0]
        nf = order
        # The tachometer and every accelerometer are filtered (a filter each);
        # the encoder and every deflection are not.
        first = 4 + len(deflection_at)
        filtered = [1, 2, *range(first, C.shape[0])]
        unfiltered = [0, *range(3, first)]
        size = npl + len(filtered) * nf
        big = np.zeros((size, size))
        bb = np.zeros(size)
        big[:npl, :npl] = A
        bb[:npl] = B
        cc = np.zeros((C.shape[0], size))
        dd = D.copy()
        cc[unfiltered, :npl] = C[unfiltered]
        for k, row in enumerate(filtered):
            sl = slice(npl + k * nf, npl + (k + 1) * nf)
            big[sl, sl] = af
            big[sl, :npl] = np.outer(bf, C[row])
            bb[sl] = bf * D[row]
            cc[row, sl] = cf
            dd[row] = 0.0
        A, B, C, D = big, bb, cc, dd
    return A, B, C, D, scale
