"""Modal parametrisation of an ARX denominator: stable by construction.

The denominator ``A(z) = 1 + a_1 z^-1 + ... + a_na z^-na`` is written as a
product of second-order sections, one per mode, and (optionally, or when
``na`` is odd) first-order sections:

    A(z) = prod_s (1 + c1_s z^-1 + c2_s z^-2) * prod_r (1 - p_r z^-1)

A second-order section is a continuous mode ``s^2 + 2 zeta wn s + wn^2``
sampled exactly (zero-order hold maps each pole ``s`` to ``exp(s ts)``):

    rho = exp(-zeta wn ts),   c2 = rho^2,
    c1 = -2 rho cos(wn ts sqrt(1 - zeta^2))        zeta < 1 (a complex pair)
    c1 = -2 rho cosh(wn ts sqrt(zeta^2 - 1))       zeta >= 1 (two real poles
                                                   exp((-zeta +- sqrt(zeta^2-1)) wn ts))

The searched coordinates are physical: the natural frequency ``f = wn / 2pi``
in Hz, in ``(0, fs/2)``, and ``log10(zeta)``. A first-order section's
coordinate is its pole ``p`` in ``(-1, 1)``, which also reaches the negative
real axis that no sampled continuous mode reaches. Every point with
``f > 0``, ``zeta > 0`` and ``|p| < 1`` is a stable polynomial, so a search
over the box never needs the stability penalty.

The coordinate vector is ``x = [f_1..f_S, log10 zeta_1..log10 zeta_S,
p_1..p_R]`` with ``2 S + R = na``.

Sections are unordered, so every model has ``S!`` equivalent coordinate
vectors; a population search does not mind, and :meth:`~ModalParametrization.
from_denominator` returns them sorted by frequency.

A stability margin (``max_radius = r_max < 1``, see
:mod:`~spiralid.sysid.estimation.linear.margin`): every pole the coordinates give
is scaled by ``r_max``, ``c1 -> r_max c1``, ``c2 -> r_max^2 c2``, ``p ->
r_max p``. In continuous time every pole moves left by ``1 / T`` (``r_max =
exp(-ts / T)``), so a section's decay is ``zeta wn + 1 / T >= 1 / T``
(``rho <= r_max``) and a first-order pole has ``|p| <= r_max``: the whole
box maps into the disc of radius ``r_max``, smoothly and one to one (no
plateau for a search or a Gauss-Newton step), and
:meth:`~ModalParametrization.from_denominator` divides the poles by
``r_max`` before it reads their coordinates. The coordinates are then the
mode's less the margin's shift; ``max_radius=None`` (the default) is the
map above exactly.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from spiralid._checks import integer

from ...data import _check_ts

__all__ = ["ModalParametrization"]

# log10(zeta) box: from a mode ringing for ~150 periods (zeta = 1e-3) to an
# overdamped pair (zeta = 10: one pole near z = 1, one near 0).
_LOG_ZETA = (-3.0, 1.0)
# Keep the frequencies strictly inside (0, fs/2): at the ends the section
# degenerates (a double pole at z = 1 or z = -rho).
_EDGE = 1e-3
_PMAX = 1.0 - 1e-6
# Real poles up to which `from_denominator` tries every pairing (8 x 105).
_ENUMERATE = 8


class ModalParametrization:
    """Second-order sections in (natural frequency, log damping ratio).

    Parameters
    ----------
    na : int
        Denominator order (>= 1).
    ts : float
        Sample time in seconds (sets the Nyquist frequency ``1 / (2 ts)``).
    real_poles : int, optional
        Number of first-order sections; default ``na % 2`` (one for an odd
        order). Must have the parity of ``na``.
    log_damping : (float, float), default (-3, 1)
        Box of ``log10(zeta)``.
    max_radius : float, optional
        A stability margin ``r_max`` in ``(0, 1]``: every pole is scaled by
        it (see the module docstring); default None, no margin.

    Attributes
    ----------
    n_sections, n_real : int
        Second- and first-order sections (``2 n_sections + n_real == na``).
    bounds : ndarray, shape (na, 2)
        The search box: frequencies in ``[1e-3, 1 - 1e-3] x fs/2``, the
        damping box, first-order poles in ``[-(1 - 1e-6), 1 - 1e-6]``.

    Examples
    --------
    One mode at 10 Hz with 5 % damping, sampled at 100 Hz: the section's
    poles are ``exp(s ts)`` of the continuous ones.

    >>> import numpy as np
    >>> par = ModalParametrization(2, ts=0.01)
    >>> a = par.to_denominator([10.0, np.log10(0.05)])
    >>> wn = 2 * np.pi * 10.0
    >>> s = -0.05 * wn + 1j * wn * np.sqrt(1 - 0.05**2)
    >>> bool(np.allclose(np.sort_complex(np.roots(np.r_[1.0, a])),
    ...                  np.sort_complex(np.exp(np.array([s, s.conjugate()]) * 0.01))))
    True
    """

    name = "modal"

    def __init__(
        self,
        na: int,
        ts: float,
        real_poles: int | None = None,
        log_damping=_LOG_ZETA,
        max_radius: float | None = None,
    ) -> None:
        na = integer(na, "na", 1)
        ts = _check_ts(ts)
        n_real = na % 2 if real_poles is None else integer(real_poles, "real_poles", 0)
        if n_real > na or (na - n_real) % 2:
            raise ValueError(
                f"`real_poles` must be at most na={na} with the parity of na; "
                f"got {real_poles!r}"
            )
        lz = np.asarray(log_damping, dtype=float)
        if lz.shape != (2,) or not np.all(np.isfinite(lz)) or lz[0] >= lz[1]:
            raise ValueError(
                f"`log_damping` must be (low, high) finite with low < high; "
                f"got {log_damping!r}"
            )
        if max_radius is not None:
            max_radius = float(max_radius)
            if not 0.0 < max_radius <= 1.0:
                raise ValueError(
                    f"`max_radius` must be in (0, 1] or None; got {max_radius!r}"
                )
        self.max_radius = max_radius
        self.na = na
        self.ts = ts
        self.n_real = n_real
        self.n_sections = (na - n_real) // 2
        nyq = 0.5 / ts
        s = self.n_sections
        box = np.empty((na, 2))
        box[:s] = (_EDGE * nyq, (1.0 - _EDGE) * nyq)
        box[s : 2 * s] = lz
        box[2 * s :] = (-_PMAX, _PMAX)
        self.bounds = box

    def __repr__(self) -> str:
        margin = "" if self.max_radius is None else f", max_radius={self.max_radius:g}"
        return (
            f"ModalParametrization(na={self.na}, ts={self.ts:g}, "
            f"sections={self.n_sections}, real_poles={self.n_real}{margin})"
        )

    def _batch(self, x) -> tuple[np.ndarray, bool]:
        arr = np.asarray(x, dtype=float)
        if arr.ndim not in (1, 2) or arr.shape[-1] != self.na:
            raise ValueError(
                f"`x` must have shape ({self.na},) or (m, {self.na}); "
                f"got shape {arr.shape}"
            )
        return np.atleast_2d(arr), arr.ndim == 1

    def sections(self, x) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(c1, c2, p)``: section coefficients, shapes (m, S), (m, S), (m, R).

        Coordinates outside :attr:`bounds` are clipped into it first, so
        every ``x`` maps to a stable polynomial.
        """
        xx, _ = self._batch(x)
        # The map is defined on the box: a search that steps outside it
        # gets the boundary's (still stable) polynomial.
        xx = np.clip(xx, self.bounds[:, 0], self.bounds[:, 1])
        s = self.n_sections
        wt = 2.0 * np.pi * xx[:, :s] * self.ts  # wn ts
        zeta = 10.0 ** xx[:, s : 2 * s]
        g = 1.0 - zeta * zeta
        rho = np.exp(-zeta * wt)
        # Overdamped (g < 0): the two real poles exp((-zeta +- sqrt(-g)) wt),
        # summed directly so a large zeta cannot overflow a cosh.
        sq = np.sqrt(np.maximum(-g, 0.0))
        pole_sum = np.exp((-zeta + sq) * wt) + np.exp((-zeta - sq) * wt)
        osc = 2.0 * rho * np.cos(np.sqrt(np.maximum(g, 0.0)) * wt)
        c1 = -np.where(g >= 0.0, osc, pole_sum)
        c2 = rho * rho
        p = xx[:, 2 * s :]
        r = self.max_radius
        if r is not None:
            # The margin: every pole z -> r z (see the module docstring).
            c1, c2, p = r * c1, (r * r) * c2, r * p
        return c1, c2, p

    def to_denominator(self, x) -> np.ndarray:
        """Map coordinates to ``a_1..a_na`` of the monic denominator.

        Parameters
        ----------
        x : array_like, shape (na,) or (m, na)

        Returns
        -------
        ndarray, same shape as `x`
        """
        xx, single = self._batch(x)
        c1, c2, p = self.sections(xx)
        m = xx.shape[0]
        poly = np.zeros((m, self.na + 1))
        poly[:, 0] = 1.0
        deg = 0
        # Multiply the sections in: poly <- poly * (1 + c1 z^-1 + c2 z^-2).
        for j in range(self.n_sections):
            new = poly.copy()
            new[:, 1 : deg + 2] += c1[:, j : j + 1] * poly[:, : deg + 1]
            new[:, 2 : deg + 3] += c2[:, j : j + 1] * poly[:, : deg + 1]
            poly, deg = new, deg + 2
        for j in range(self.n_real):
            new = poly.copy()
            new[:, 1 : deg + 2] -= p[:, j : j + 1] * poly[:, : deg + 1]
            poly, deg = new, deg + 1
        a = poly[:, 1:]
        return a[0] if single else a

    def jacobian(self, x, step: float = 1e-7) -> np.ndarray:
        """``d a_i / d x_j`` at one point, shape (na, na), by central differences.

        The map is smooth in the box (``cos(sqrt(g) w)`` continues analytically
        into ``cosh`` across ``zeta = 1``); a relative step of 1e-7 of the box
        width gives about 8 correct digits, ample for Gauss-Newton steps.
        """
        xx, single = self._batch(x)
        if not single:
            raise ValueError(f"`x` must be a single point; got shape {xx.shape}")
        h = step * (self.bounds[:, 1] - self.bounds[:, 0])
        pts = np.vstack([xx[0] + np.diag(h), xx[0] - np.diag(h)])
        a = self.to_denominator(pts)
        return ((a[: self.na] - a[self.na :]) / (2.0 * h)[:, None]).T

    def from_denominator(self, a) -> np.ndarray:
        """Coordinates of the nearest representable denominator, in the box.

        Poles outside the unit circle are first reflected in (``z -> 1/conj z``);
        with a margin ``r_max`` the poles are divided by it first, so those
        outside radius ``r_max`` are reflected about that circle.
        Complex pairs become second-order sections; the real poles of largest
        magnitude fill the first-order sections and the rest pair up into
        overdamped sections, where a pair of positive poles is exact and any other pair
        is replaced by its nearest representable one (a double pole at the
        pair's mean, a complex pair at the Nyquist edge for a negative mean).
        Coordinates are clipped to :attr:`bounds`.

        Parameters
        ----------
        a : array_like, shape (na,)

        Returns
        -------
        ndarray, shape (na,), sections sorted by frequency
        """
        a = np.asarray(a, dtype=float)
        if a.shape != (self.na,) or not np.all(np.isfinite(a)):
            raise ValueError(
                f"`a` must be a finite vector of shape ({self.na},); got {a!r}"
            )
        z = np.roots(np.r_[1.0, a])
        if self.max_radius is not None:
            # Coordinates describe the poles before the margin's scaling.
            z = z / self.max_radius
        mag = np.abs(z)
        outside = mag >= 1.0
        z[outside] = 1.0 / np.conj(z[outside])
        tol = 1e-9
        upper = z[z.imag > tol]
        real = np.sort(z[np.abs(z.imag) <= tol].real)
        # Too many complex pairs for the sections: the smallest ones become
        # two real poles at their magnitude (rare; only with real_poles > na%2).
        upper = upper[np.argsort(-np.abs(upper))]
        while upper.size > self.n_sections:
            extra, upper = upper[-1], upper[:-1]
            real = np.sort(np.r_[real, np.abs(extra), np.abs(extra)])
        modes = [self._mode_of_pole(zc) for zc in upper]
        firsts, paired = self._assign_real(real, self.n_sections - upper.size)
        modes += paired
        freqs = np.array([f for f, _ in modes], dtype=float)
        logz = np.array([lz for _, lz in modes], dtype=float)
        order = np.argsort(freqs)
        x = np.r_[freqs[order], logz[order], firsts]
        return np.clip(x, self.bounds[:, 0], self.bounds[:, 1])

    def _assign_real(self, real: np.ndarray, n_pairs: int):
        """Split real poles into first-order sections and overdamped pairs.

        Up to :data:`_ENUMERATE` real poles: every choice of first-order
        poles and every pairing of the rest (at most 8 x 105), keeping the
        one whose coordinates leave the box least, so a denominator built
        from the box maps back exactly. Beyond, the count of pairings grows
        as (n - 1)!! (2 million at 16 poles), so a rule pairs them instead
        (`_assign_real_by_rule`), in O(n log n).
        """
        if real.size > _ENUMERATE:
            return self._assign_real_by_rule(real, n_pairs)
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        s = self.n_sections
        width = np.r_[hi[0] - lo[0], hi[s] - lo[s]] if s else np.ones(2)
        box = np.array([[lo[0], hi[0]], [lo[s], hi[s]]]) if s else None
        best = None
        for chosen in combinations(range(real.size), min(self.n_real, real.size)):
            firsts = real[list(chosen)]
            rest = np.delete(real, list(chosen))
            for pairing in _pairings(list(range(rest.size))):
                modes = [self._mode_of_real_pair(rest[list(pr)]) for pr in pairing]
                miss = 0.0
                for mode in modes:
                    v = np.asarray(mode)
                    miss += float(
                        np.sum(
                            (
                                np.maximum(box[:, 0] - v, 0)
                                + np.maximum(v - box[:, 1], 0)
                            )
                            / width
                        )
                    )
                if best is None or miss < best[0]:
                    best = (miss, firsts, modes)
                if miss == 0.0:
                    break
            if best[0] == 0.0:
                break
        _, firsts, modes = best
        # Pad if the polynomial had fewer real poles than first-order slots.
        firsts = np.r_[firsts, np.zeros(self.n_real - firsts.size)]
        return firsts, modes[:n_pairs]

    def _assign_real_by_rule(self, real: np.ndarray, n_pairs: int):
        """The real poles of largest magnitude fill the first-order sections;
        the rest, sorted by value, pair either with their neighbours (a pair
        of close poles is a section near critical damping) or from the
        outside in (a slow pole with a fast one, as an overdamped section's
        two poles are), whichever leaves the box less: two pairings, not
        (n - 1)!!. Equal poles, as the zero model's, pair with each other."""
        by_size = np.argsort(-np.abs(real), kind="stable")
        chosen = np.sort(by_size[: self.n_real])
        firsts = np.r_[real[chosen], np.zeros(self.n_real - chosen.size)]
        rest = np.sort(np.delete(real, chosen))[::-1]
        half = rest.size // 2
        neighbours = [rest[i : i + 2] for i in range(0, 2 * half, 2)]
        outside_in = [rest[[i, rest.size - 1 - i]] for i in range(half)]
        candidates = [
            [self._mode_of_real_pair(pair) for pair in pairing]
            for pairing in (neighbours, outside_in)
        ]
        modes = min(candidates, key=self._box_miss)
        return firsts, modes[:n_pairs]

    def _box_miss(self, modes) -> float:
        """How far sections' (frequency, log damping) leave the box, in
        widths of the box."""
        s = self.n_sections
        if not s or not modes:
            return 0.0
        box = self.bounds[[0, s]]
        v = np.asarray(modes, dtype=float)
        out = np.maximum(box[:, 0] - v, 0) + np.maximum(v - box[:, 1], 0)
        return float(np.sum(out / (box[:, 1] - box[:, 0])))

    def _mode_of_pole(self, z: complex) -> tuple[float, float]:
        s = np.log(max(abs(z), 1e-300)) + 1j * np.angle(z)
        s = s / self.ts
        wn = abs(s)
        zeta = -s.real / wn if wn > 0 else 1.0
        return wn / (2 * np.pi), float(np.log10(max(zeta, 1e-300)))

    def _mode_of_real_pair(self, pair: np.ndarray) -> tuple[float, float]:
        p1, p2 = (float(v) for v in pair)
        if p1 > 0 and p2 > 0:
            l1, l2 = np.log(p1), np.log(p2)
            wt = np.sqrt(l1 * l2)
            zeta = -(l1 + l2) / (2.0 * wt)
            return wt / (2 * np.pi * self.ts), float(np.log10(zeta))
        mean = 0.5 * (p1 + p2)
        if mean > 0:
            return self._mode_of_real_pair(np.array([mean, mean]))
        # A negative pair: a complex pair of the same magnitude at (nearly)
        # the Nyquist angle.
        r = max(abs(mean), 1e-12)
        return self._mode_of_pole(r * np.exp(1j * np.pi * (1.0 - _EDGE)))

    def initial_points(self, m: int, rng=None) -> np.ndarray:
        """``m`` points uniform in :attr:`bounds` (each a stable denominator)."""
        m = integer(m, "m", 1)
        gen = np.random.default_rng(rng)
        return gen.uniform(self.bounds[:, 0], self.bounds[:, 1], size=(m, self.na))


def _pairings(items: list):
    """Every way to split `items` (even length) into unordered pairs."""
    if not items:
        yield []
        return
    first = items[0]
    for i in range(1, len(items)):
        rest = items[1:i] + items[i + 1 :]
        for tail in _pairings(rest):
            yield [(first, items[i]), *tail]
