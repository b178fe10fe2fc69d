"""Mode shapes from residues, with intervals, and the MAC: :class:`ModeShapes`.

Every output ``i`` of a shared-denominator model,
``G_i(z) = B_i(z^-1) / (A(z^-1) (1 - z^-1)^k_i)``, is a sum of partial
fractions ``c_ir / (1 - p_r z^-1)`` (``scipy.signal.residuez``'s form) over
the shared poles. For a mode ``r`` of a structure with proportional
damping, ``c_ir`` is the mode's deflection at sensor ``i`` times a factor
common to every sensor (the input's participation, the pole's, the
sampling's and a filter every sensor shares), so the vector ``c_r`` over the
outputs is the mode's shape at the sensors, measured in the sensors'
quantity. The residue of mode ``r`` at a simple root ``p`` of
``A_i(z) = z^n + a_1 z^(n-1) + ...`` (the output's whole denominator, its
integrators included) is

    c = sum_j b_j p^(n-1-j) / A_i'(p)

with ``b_j`` the coefficient of ``z^-j`` (delays included); its gradient in
the coefficients follows in closed form (:func:`residue_gradient`), and the
delta method carries the estimate's covariance into each shape component.

Normalisation. A shape is only defined up to a complex factor: each is
scaled to unit Euclidean norm over the outputs and turned so that its
largest-magnitude component is real and positive. A lightly damped mode's
shape is then nearly real; its imaginary parts measure how far the data
stray from a real (proportionally damped) mode. The norm adds every output
in its own unit: shapes compare sensors of one quantity (accelerometers, or
deflections).

Several inputs. This module is written for one input: shapes are indexed
``[mode, output]``. A record of ``m`` inputs gives a numerator per
input-output pair; :func:`output_residues` run once per input gives
residues ``[mode, input, output]``, each input's row the same shape up to
that input's participation factor.

MAC. The modal assurance criterion of two shapes is
``|phi_a^H phi_b|^2 / ((phi_a^H phi_a)(phi_b^H phi_b))``: 1 for the same
shape up to a complex factor, 0 for orthogonal ones (:func:`mac`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

from . import _fields
from .polynomials import with_integrator

__all__ = [
    "ModeShapes",
    "mac",
    "mode_shapes",
    "normalise_shapes",
    "output_residues",
    "pair_shapes",
    "residue_gradient",
]


def mac(shapes_a, shapes_b=None) -> np.ndarray:
    """The modal assurance criterion between two sets of shapes.

    Parameters
    ----------
    shapes_a : array_like, shape (m_a, p) or (p,)
        Shapes as rows (real or complex), one component per sensor.
    shapes_b : array_like, shape (m_b, p) or (p,), optional
        The reference set; default `shapes_a` (the auto-MAC).

    Returns
    -------
    ndarray, shape (m_a, m_b)
        ``|phi_a^H phi_b|^2 / ((phi_a^H phi_a)(phi_b^H phi_b))`` for each
        pair, in [0, 1].

    Examples
    --------
    >>> mac([1.0, 1.0], [[1.0, 0.0], [2j, 2j]]).round(12).tolist()
    [[0.5, 1.0]]
    """
    a = _shape_rows(shapes_a, "shapes_a")
    b = a if shapes_b is None else _shape_rows(shapes_b, "shapes_b")
    if a.shape[1] != b.shape[1]:
        raise ValueError(
            f"`shapes_b` must have as many components as `shapes_a` ({a.shape[1]}); "
            f"got {b.shape[1]}"
        )
    na = np.einsum("ij,ij->i", a.conj(), a).real
    nb = np.einsum("ij,ij->i", b.conj(), b).real
    if not (np.all(na > 0) and np.all(nb > 0)):
        raise ValueError("every shape must have a nonzero component")
    cross = a.conj() @ b.T
    return np.abs(cross) ** 2 / np.outer(na, nb)


def _shape_rows(value, name: str) -> np.ndarray:
    """`value` as a 2-D complex array of finite shapes (rows)."""
    try:
        arr = np.asarray(value, dtype=complex)
    except (TypeError, ValueError):
        raise TypeError(
            f"`{name}` must be an array of numbers; got {type(value).__name__}"
        ) from None
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.size == 0 or not np.all(np.isfinite(arr)):
        raise ValueError(
            f"`{name}` must be a non-empty finite (m, p) or (p,) array; got shape "
            f"{np.shape(value)}"
        )
    return arr


def normalise_shapes(shapes) -> np.ndarray:
    """Each shape scaled to unit norm, its largest component real positive.

    Parameters
    ----------
    shapes : array_like, shape (m, p) or (p,)
        Shapes as rows.

    Returns
    -------
    ndarray of complex, shape (m, p)

    Examples
    --------
    >>> psi = normalise_shapes([3j, -4j])
    >>> psi.real.round(12).tolist(), float(abs(psi.imag).max())
    ([[-0.6, 0.8]], 0.0)
    """
    phi = _shape_rows(shapes, "shapes")
    norm = np.linalg.norm(phi, axis=1)
    if not np.all(norm > 0):
        raise ValueError("every shape must have a nonzero component")
    big = phi[np.arange(phi.shape[0]), np.argmax(np.abs(phi), axis=1)]
    return phi * (np.abs(big) / big / norm)[:, None]


def residue_gradient(den, num, pole) -> tuple[complex, np.ndarray, np.ndarray]:
    """The residue ``c`` of ``num(z^-1) / den(z^-1)`` at a simple pole, in
    ``scipy.signal.residuez``'s form ``c / (1 - p z^-1)``, and its gradient.

    Parameters
    ----------
    den : array_like, shape (n,)
        ``a_1..a_n`` of the denominator ``1 + a_1 z^-1 + ...``.
    num : array_like, shape (L,)
        ``b_0..b_(L-1)``, the coefficients of ``z^0..z^-(L-1)``.
    pole : complex
        A simple root of the denominator.

    Returns
    -------
    c : complex
    dc_da : ndarray of complex, shape (n,)
        ``dc / da_k``, the pole moving with the coefficients.
    dc_db : ndarray of complex, shape (L,)

    Examples
    --------
    >>> c, _, _ = residue_gradient([-0.5], [1.0, 1.0], 0.5)
    >>> complex(c)   # (1 + z^-1) / (1 - 0.5 z^-1) = -2 + 3 / (1 - 0.5 z^-1)
    (3+0j)
    """
    a = np.asarray(den, dtype=float).ravel()
    b = np.asarray(num, dtype=float).ravel()
    p = complex(pole)
    n = a.size
    poly = np.r_[1.0, a]
    slope = np.polyval(np.polyder(poly), p)
    curve = np.polyval(np.polyder(poly, 2), p) if n > 1 else 0.0
    j = np.arange(b.size)
    powers = p ** (n - 1.0 - j)
    c = complex(b @ powers) / slope
    dc_db = powers / slope
    dc_dp = (complex(b @ ((n - 1.0 - j) * p ** (n - 2.0 - j))) - c * curve) / slope
    k = np.arange(1, n + 1)
    dp_da = -(p ** (n - k)) / slope
    # A'(p) holds a_k through (n - k) p^(n-k-1), at a fixed pole.
    dc_da = -c * (n - k) * p ** (n - k - 1.0) / slope + dc_dp * dp_da
    return c, dc_da, dc_db


def _integrator_map(na: int, count: int) -> np.ndarray:
    """``T`` with ``d with_integrator(a, count) / da = T``: the integrators
    enter the whole denominator's coefficients linearly."""
    factor = np.array([1.0])
    for _ in range(count):
        factor = np.convolve(factor, [1.0, -1.0])
    T = np.zeros((na + count, na))
    for col in range(na):
        T[col : col + count + 1, col] = factor
    return T


def output_residues(a, b, poles, *, nk: int = 0, integrators=None):
    """Each output's residue at each pole, and their gradients in the
    parameters ``[a, b_1, .., b_p]``.

    Parameters
    ----------
    a : array_like, shape (na,)
        The shared denominator ``1 + a_1 q^-1 + ...``.
    b : array_like, shape (p, nb)
        One numerator per output, coefficients of ``q^-nk .. q^-(nk+nb-1)``
        (one input: a second input's numerators are a second call).
    poles : array_like of complex, shape (m,)
        Simple roots of ``A`` (one per mode).
    nk : int
        The numerators' delay.
    integrators : sequence of int, optional
        Each output's known integrators outside ``A`` (default none).

    Returns
    -------
    residues : ndarray of complex, shape (m, p)
    gradient : ndarray of complex, shape (m, p, na + p nb)
    """
    a = np.asarray(a, dtype=float).ravel()
    b = np.atleast_2d(np.asarray(b, dtype=float))
    poles = np.atleast_1d(np.asarray(poles, dtype=complex))
    p, nb = b.shape
    na = a.size
    counts = (0,) * p if integrators is None else tuple(int(k) for k in integrators)
    residues = np.zeros((poles.size, p), complex)
    gradient = np.zeros((poles.size, p, na + p * nb), complex)
    for i, k in enumerate(counts):
        T = _integrator_map(na, k)
        den = with_integrator(a, k)
        num = np.r_[np.zeros(nk), b[i]]
        cols = slice(na + i * nb, na + (i + 1) * nb)
        for r, pole in enumerate(poles):
            c, dc_da, dc_db = residue_gradient(den, num, pole)
            residues[r, i] = c
            gradient[r, i, :na] = dc_da @ T
            gradient[r, i, cols] = dc_db[nk:]
    return residues, gradient


@dataclass(frozen=True)
class ModeShapes:
    """The shapes of a shared denominator's modes over its outputs.

    Attributes
    ----------
    poles : ndarray of complex, shape (m,)
        One pole per mode (positive imaginary part), in the order of the
        model's modes table (by frequency).
    frequency : ndarray, shape (m,)
        The modes' natural frequencies in Hz.
    residues : ndarray of complex, shape (m, p)
        Each output's residue at each mode (``residuez``'s form, in the
        output's unit per input unit).
    shapes : ndarray of complex, shape (m, p)
        The residues normalised (:func:`normalise_shapes`): unit norm, the
        largest component real and positive.
    real_se, imag_se : ndarray, shape (m, p)
        Standard errors of each normalised component's real and imaginary
        parts (delta method from the covariance of every parameter; NaN
        without one).
    output_names : tuple of str
    level : float
        The intervals' confidence level.
    """

    poles: np.ndarray
    frequency: np.ndarray
    residues: np.ndarray
    shapes: np.ndarray
    real_se: np.ndarray
    imag_se: np.ndarray
    output_names: tuple[str, ...]
    level: float = 0.95

    def __len__(self) -> int:
        return int(self.poles.size)

    @property
    def _z(self) -> float:
        return float(stats.norm.ppf(0.5 + self.level / 2))

    @property
    def real_interval(self) -> np.ndarray:
        """Shape (m, p, 2): each component's real part's interval at
        :attr:`level`."""
        half = self._z * self.real_se
        return np.stack([self.shapes.real - half, self.shapes.real + half], axis=-1)

    @property
    def imag_interval(self) -> np.ndarray:
        """Shape (m, p, 2): each component's imaginary part's interval."""
        half = self._z * self.imag_se
        return np.stack([self.shapes.imag - half, self.shapes.imag + half], axis=-1)

    @property
    def auto_mac(self) -> np.ndarray:
        """Shape (m, m): the MAC between every two modes (1 on the
        diagonal; off it, how alike two modes look to these sensors);
        empty without modes."""
        return mac(self.shapes) if len(self) else np.zeros((0, 0))

    def mac(self, reference) -> np.ndarray:
        """The MAC of each mode's shape with each reference shape.

        Parameters
        ----------
        reference : array_like, shape (k, p) or (p,)
            Shapes at the same outputs, in the same order (e.g. the finite
            elements' at the sensors' positions).

        Returns
        -------
        ndarray, shape (m, k)
        """
        return mac(self.shapes, reference)

    def to_dict(self) -> dict:
        """Plain Python values, one dict per mode (for JSON)."""
        lo, hi = np.moveaxis(self.real_interval, -1, 0)
        return {
            "level": self.level,
            "output_names": list(self.output_names),
            "modes": [
                {
                    "frequency_hz": float(self.frequency[r]),
                    "shape_real": self.shapes[r].real.tolist(),
                    "shape_imag": self.shapes[r].imag.tolist(),
                    "real_interval": [
                        [_fields.plain(x), _fields.plain(y)]
                        for x, y in zip(lo[r], hi[r], strict=True)
                    ],
                }
                for r in range(len(self))
            ],
            "auto_mac": self.auto_mac.tolist() if len(self) else [],
        }

    def __str__(self) -> str:
        if not len(self):
            return "no modes (no complex pole pair)"
        widths = [max(16, len(n)) for n in self.output_names]
        head = f"{'mode':>4}  {'Hz':>9}  " + "  ".join(
            f"{n:>{w}}" for n, w in zip(self.output_names, widths, strict=True)
        )
        lines = [head]
        for r in range(len(self)):
            cells = []
            for i, w in enumerate(widths):
                value = f"{self.shapes[r, i].real:+.3f}"
                se = self.real_se[r, i]
                if np.isfinite(se):
                    value += f" +-{self._z * se:.3f}"
                cells.append(f"{value:>{w}}")
            lines.append(f"{r + 1:>4}  {self.frequency[r]:9.4g}  " + "  ".join(cells))
        pct = round(100 * self.level)
        lines.append(f"(real parts, unit norm; +- the {pct} % interval's half width)")
        return "\n".join(lines)


def mode_shapes(
    a,
    b,
    ts: float,
    *,
    nk: int = 0,
    integrators=None,
    factor=None,
    output_names=None,
    poles=None,
    level: float = 0.95,
) -> ModeShapes:
    """The shapes of the modes of ``B_i(q) / A(q)`` over the outputs ``i``.

    Parameters
    ----------
    a : array_like, shape (na,)
        The shared denominator's coefficients.
    b : array_like, shape (p, nb)
        One numerator per output (one input).
    ts : float
        Sample time in seconds.
    nk : int
        The numerators' delay.
    integrators : sequence of int, optional
        Each output's known integrators outside ``A``.
    factor : array_like, shape (k, na + p nb), optional
        A square-root factor ``R`` of the covariance of ``[a, b_1, ..,
        b_p]`` (``C = R^T R``); without it the standard errors are NaN.
    output_names : sequence of str, optional
        Default ``y1, y2, ...``.
    poles : array_like of complex, optional
        The modes' poles (default: the complex pairs of ``A``, one each, by
        frequency, as :func:`~spiralid.sysid.models.modes.mode_table`).
    level : float, default 0.95
        Confidence level of the intervals.

    Returns
    -------
    ModeShapes

    Examples
    --------
    >>> import numpy as np
    >>> p = 0.95 * np.exp(0.3j)
    >>> a = np.poly([p, p.conjugate()]).real[1:]
    >>> s = mode_shapes(a, [[1.0, 0.0], [-2.0, 0.0]], 0.01, nk=1)
    >>> s.shapes.round(6).real.tolist()
    [[-0.447214, 0.894427]]
    """
    from .modes import mode_table

    a = np.asarray(a, dtype=float).ravel()
    b = np.atleast_2d(np.asarray(b, dtype=float))
    if poles is None:
        poles = mode_table(a, [1.0], ts, shares=False).poles
    poles = np.atleast_1d(np.asarray(poles, dtype=complex))
    names = tuple(output_names or (f"y{i + 1}" for i in range(b.shape[0])))
    if len(names) != b.shape[0]:
        raise ValueError(
            f"`output_names` must name each of the {b.shape[0]} outputs; got {names}"
        )
    s = np.log(poles) / ts
    frequency = np.abs(s) / (2 * np.pi)
    residues, gradient = output_residues(a, b, poles, nk=nk, integrators=integrators)
    m, p = residues.shape
    shapes = normalise_shapes(residues) if m else np.zeros((0, p), complex)
    real_se = np.full((m, p), np.nan)
    imag_se = np.full((m, p), np.nan)
    if factor is not None and m:
        root = np.asarray(factor, dtype=float)
        if root.ndim != 2 or root.shape[1] != gradient.shape[2]:
            raise ValueError(
                f"`factor` must have {gradient.shape[2]} columns (a and every "
                f"numerator); got shape {root.shape}"
            )
        for r in range(m):
            # Real coordinates: the normalisation is not holomorphic.
            d_phi = np.vstack([gradient[r].real, gradient[r].imag])
            d_psi = _normalisation_jacobian(residues[r]) @ d_phi
            se = np.linalg.norm(root @ d_psi.T, axis=0)
            real_se[r], imag_se[r] = se[:p], se[p:]
    return ModeShapes(
        poles=poles,
        frequency=frequency,
        residues=residues,
        shapes=shapes,
        real_se=real_se,
        imag_se=imag_se,
        output_names=names,
        level=level,
    )


def _normalisation_jacobian(phi: np.ndarray) -> np.ndarray:
    """``d [Re psi, Im psi] / d [Re phi, Im phi]`` of one shape's
    normalisation, by central differences (it is smooth and scale-free: a
    step of 1e-6 of the norm is exact to about 1e-12)."""
    p = phi.size
    h = 1e-6 * float(np.linalg.norm(phi))
    out = np.zeros((2 * p, 2 * p))
    for k in range(2 * p):
        step = np.zeros(p, complex)
        step[k % p] = h if k < p else 1j * h
        hi = normalise_shapes(phi + step)[0]
        lo = normalise_shapes(phi - step)[0]
        diff = (hi - lo) / (2 * h)
        out[:, k] = np.r_[diff.real, diff.imag]
    return out


def pair_shapes(model, j: int) -> ModeShapes:
    """The shapes of a shared-denominator `model`'s modes as its input `j`
    excites them: each output's residues of ``B_ij / A``, with 95 %
    intervals from the covariance of that input's numerators and the
    denominator (``model.shape_factor``, where the fit kept one).

    Parameters
    ----------
    model : SharedDenominatorModel
        The fitted model.
    j : int
        The input's 0-based index.

    Returns
    -------
    ModeShapes
    """
    nb, m = model.arx.nb, model.n_inputs
    mine = np.arange(j * nb, (j + 1) * nb)
    factor = model.shape_factor
    if factor is not None and m > 1:
        # A factor's columns of a subset of the parameters factor the
        # covariance of that subset: C_sub = R[:, S]' R[:, S].
        na = model.a.size
        rows = [na + i * m * nb + mine for i in range(model.b.shape[0])]
        factor = factor[:, np.r_[np.arange(na), *rows]]
    return mode_shapes(
        model.a,
        model.b[:, mine],
        model.ts,
        nk=model.arx.nk,
        integrators=model.integrators,
        factor=factor,
        output_names=model.output_names,
        poles=model.modes.table.poles,
    )
