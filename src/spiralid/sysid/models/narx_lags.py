"""What the NARX structures share: the signals' scaling, the lags and the
regressors built from them, and the checks of their orders (see
:mod:`.narx` for the model they make up)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..data import IOData


def _integrators(value) -> int:
    """`integrator` as a count 0, 1 or 2 (False and True are 0 and 1)."""
    if isinstance(value, bool | np.bool_):
        return int(value)
    if isinstance(value, int | np.integer) and 0 <= value <= 2:
        return int(value)
    raise ValueError(f"`integrator` must be False, True, 0, 1 or 2; got {value!r}")


def _order(value, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise ValueError(f"`{name}` must be an integer >= {minimum}; got {value!r}")
    if value < minimum:
        raise ValueError(f"`{name}` must be an integer >= {minimum}; got {value!r}")
    return int(value)


def _one_layer(hidden) -> tuple[int, ...]:
    """A network's `hidden` sizes checked: () or one hidden layer (h,), the
    NARX's and the neural state space's one check."""
    try:
        layers = tuple(hidden)
    except TypeError:
        layers = None
    if layers is None or len(layers) > 1:
        raise ValueError(
            "`hidden` must be () or one hidden layer (h,) (deeper networks are "
            f"not built); got {hidden!r}"
        )
    return tuple(_order(h, "hidden[0]", 1) for h in layers)


@dataclass(frozen=True)
class Scaling:
    """Affine scaling of the signals: ``(u - u_shift) / u_scale`` and the
    same for the output (for an integrating model, of its increment).

    Parameters
    ----------
    u_shift, u_scale, y_shift, y_scale : float
        Shifts and (positive) scales.
    """

    u_shift: float = 0.0
    u_scale: float = 1.0
    y_shift: float = 0.0
    y_scale: float = 1.0

    @classmethod
    def from_data(cls, data: IOData, integrator: bool = False) -> Scaling:
        """Mean and standard deviation of the estimation record's signals
        (of the output's increments for an integrating model, unshifted so
        that rest stays zero).

        Parameters
        ----------
        data : IOData
            Estimation record.
        integrator : bool
            Scale the output's increments instead of the output.
        """
        u, y = data.u, data.y
        us = float(np.std(u)) or 1.0
        if integrator:
            d = np.diff(y, prepend=0.0)
            return cls(float(np.mean(u)), us, 0.0, float(np.std(d)) or 1.0)
        return cls(float(np.mean(u)), us, float(np.mean(y)), float(np.std(y)) or 1.0)


class _Lags:
    """What both structures share: lags, scaled signals and regressors."""

    ny: int
    nu: int
    nk: int
    integrator: bool

    @property
    def n_regressors(self) -> int:
        """``ny + nu``: past outputs (or increments) and inputs."""
        return self.ny + self.nu

    @property
    def max_lag(self) -> int:
        """Samples of measured history the first full regressor needs."""
        return max(self.ny + int(self.integrator > 0), self.nk + self.nu - 1)

    def check_length(self, data: IOData, name: str = "data") -> None:
        """Raise ``ValueError`` if `data` is too short for this structure.

        Parameters
        ----------
        data : IOData
        name : str
            The argument's name in the message.
        """
        need = self.max_lag + self.n_params + 1
        if data.n < need:
            raise ValueError(
                f"`{name}` is too short for {self}: needs at least {need} samples "
                f"({self.n_params} parameters after {self.max_lag} initial "
                f"samples, plus one); got {data.n}"
            )

    def _target(self, y: np.ndarray, s: Scaling) -> np.ndarray:
        """The scaled signal the map predicts (output or its increment)."""
        if self.integrator:
            return np.diff(y, prepend=0.0) / s.y_scale
        return (y - s.y_shift) / s.y_scale

    def input_lags(self, u: np.ndarray, s: Scaling) -> np.ndarray:
        """Scaled input regressors ``U[t, j] = u~(t - nk - j)``, rest before 0.

        Parameters
        ----------
        u : ndarray, shape (N,)
        s : Scaling
        """
        n = u.size
        us = (np.r_[np.zeros(self.nk + self.nu), u] - s.u_shift) / s.u_scale
        off = self.nk + self.nu
        out = np.empty((n, self.nu))
        for j in range(self.nu):
            lag = self.nk + j
            out[:, j] = us[off - lag : off - lag + n]
        return out

    def rest_history(self, s: Scaling) -> np.ndarray:
        """The ``ny`` scaled past outputs of a system at rest.

        Parameters
        ----------
        s : Scaling
        """
        z0 = 0.0 if self.integrator else (0.0 - s.y_shift) / s.y_scale
        return np.full(self.ny, z0)

    def regressors(self, u, y, s: Scaling) -> tuple[np.ndarray, np.ndarray]:
        """One-step regressors from measured signals and the scaled target.

        Parameters
        ----------
        u, y : ndarray, shape (N,)
            Measured input and output.
        s : Scaling

        Returns
        -------
        phi : ndarray, shape (N, ny + nu)
        target : ndarray, shape (N,)
        """
        z = self._target(y, s)
        n = z.size
        zp = np.r_[self.rest_history(s)[::-1], z]
        phi = np.empty((n, self.n_regressors))
        for i in range(self.ny):
            phi[:, i] = zp[self.ny - 1 - i : self.ny - 1 - i + n]
        phi[:, self.ny :] = self.input_lags(u, s)
        return phi, z

    def _unscale(self, z: np.ndarray, s: Scaling, y0: float = 0.0) -> np.ndarray:
        if self.integrator:
            return y0 + np.cumsum(z * s.y_scale, axis=-1)
        return s.y_shift + s.y_scale * z

    def _history(self, y, s: Scaling, initial: str):
        """Start of the free run: (first simulated index, scaled history,
        output before it)."""
        if initial == "rest":
            return 0, self.rest_history(s), 0.0
        t0 = self.max_lag
        z = self._target(np.asarray(y, dtype=float)[: t0 + 1], s)
        return t0, z[t0 - self.ny : t0], float(y[t0 - 1]) if t0 > 0 else 0.0
