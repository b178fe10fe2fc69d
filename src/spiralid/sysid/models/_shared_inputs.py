"""A shared-denominator model of several inputs (private): its free run,
one-step prediction, modes and state-space realisation, which
:class:`~spiralid.sysid.models.shared.SharedDenominatorModel` calls when
it has more than one input (its single-input code is left as it was).

Each output is the sum over the inputs, ``y_i = sum_j B_ij / A u_j``, every
pair over the same poles (and the output's known integrators).
"""

from __future__ import annotations

import numpy as np
from scipy import signal
from scipy.linalg import block_diag

from .arx import ARX
from .modes import mode_table
from .polynomials import with_integrator


def one_per(values, p: int, name: str, default, what="output") -> tuple:
    """`values` as a tuple of p entries of `default`'s type (p defaults
    when empty), one per output (or input)."""
    kind = type(default)
    values = tuple(kind(v) for v in values) or (default,) * p
    if len(values) != p:
        raise ValueError(
            f"`{name}` must have one entry per {what} ({p}); got {len(values)}"
        )
    return values


def check_inputs(self) -> None:
    """A shared-denominator model `self`'s inputs: one name, unit and
    offset per input; with one, the provenance's own (its input_name,
    input_unit and u_offset)."""
    if isinstance(self.input_name, tuple | list) and not self.input_names:
        # A record's several inputs, as IOData holds them.
        self.input_names = tuple(self.input_name)
    names = tuple(str(n) for n in self.input_names)
    if len(names) <= 1:
        if names:
            self.input_name = names[0]
        unit = self.input_units[0] if len(self.input_units) == 1 else None
        offset = self.u_offsets[0] if len(self.u_offsets) == 1 else None
        self.input_unit = self.input_unit if unit is None else str(unit)
        self.u_offset = self.u_offset if offset is None else float(offset)
        self.input_names = (self.input_name,)
        self.input_units = (self.input_unit,)
        self.u_offsets = (float(self.u_offset),)
        return
    m = len(names)
    if len(set(names)) != m:
        raise ValueError(f"`input_names` must name each input once; got {names}")
    self.input_names = names
    self.input_units = one_per(self.input_units, m, "input_units", "", "input")
    self.u_offsets = one_per(self.u_offsets, m, "u_offsets", 0.0, "input")
    if not all(np.isfinite(self.u_offsets)):
        raise ValueError(f"`u_offsets` must be finite; got {self.u_offsets}")
    # The provenance's scalars label the inputs together (its one offset
    # is the per-input u_offsets' business).
    self.input_name = ", ".join(names)
    self.input_unit = ", ".join(u for u in self.input_units if u)
    self.u_offset = 0.0


def simo_state_space(a, b, arx: ARX, integrators):
    """``(A, B, C, D)`` of the outputs ``b_i / (A (1 - z^-1)^k_i)`` of one
    input, ``b`` of shape (p, nb)."""
    # Over the common denominator A (1 - z^-1)^kmax: each numerator times
    # the integrators its output lacks.
    kmax = max(integrators)
    common = ARX(arx.na + kmax, arx.nb + kmax, arx.nk)
    polys = []
    for i, k in enumerate(integrators):
        extra = np.convolve(b[i], np.r_[1.0, with_integrator([], kmax - k)])
        extra = np.r_[extra, np.zeros(common.nb - extra.size)]
        theta = np.r_[with_integrator(a, kmax), extra]
        polys.append(common.polynomials(theta))
    num = np.array([n for n, _ in polys])
    # Leading zero columns (the delay nk) are a strictly proper system's:
    # left in, scipy warns of badly conditioned coefficients.
    lead = np.argmax(np.any(num != 0.0, axis=0)) if np.any(num) else 0
    return signal.tf2ss(num[:, lead:], polys[0][1])


def _inputs(model, u) -> np.ndarray:
    """`u` as (N, m) for `model`'s m inputs; a one-line ValueError otherwise."""
    u = np.asarray(u, dtype=float)
    if u.ndim != 2 or u.shape[1] != model.n_inputs:
        raise ValueError(
            f"`u` must have one column per input ({model.n_inputs}: "
            f"{model.input_names}); got shape {u.shape}"
        )
    return u


def simulate(model, u) -> np.ndarray:
    """Every output's free run from rest, shape (N, p)."""
    u = _inputs(model, u)
    out = np.zeros((u.shape[0], model.n_outputs))
    for i in range(model.n_outputs):
        arx = model.output_arx(i)
        for j in range(model.n_inputs):
            out[:, i] += arx.simulate(model.output_theta(i, j), u[:, j])
    return out


def _polynomials(model, i: int, j: int) -> tuple[np.ndarray, np.ndarray]:
    """``(B_ij, A_i)`` in ``q^-1`` with the delay and output `i`'s
    integrators (``A_i`` monic)."""
    den = np.r_[1.0, with_integrator(model.a, model.integrators[i])]
    num = np.r_[np.zeros(model.arx.nk), model.numerator(i, j)]
    return num, den


def predict(model, data) -> np.ndarray:
    """One-step-ahead prediction of every output on `data` (a record of
    the model's inputs and outputs), shape (N, p): ``yhat_i = y_i - (A_i
    y_i - sum_j B_ij u_j)`` with zeros before the record."""
    u = _inputs(model, data.inputs)
    out = []
    for i, name in enumerate(model.output_names):
        y = data.output(name).y
        num, den = _polynomials(model, i, 0)
        error = signal.lfilter(den, [1.0], y)
        for j in range(model.n_inputs):
            num, _ = _polynomials(model, i, j)
            error -= signal.lfilter(num, [1.0], u[:, j])
        out.append(y - error)
    return np.column_stack(out)


def modes(model, shared_modes):
    """The shared modes (a `shared_modes`, the model module's
    :class:`~spiralid.sysid.models.shared.SharedModes`); each output's share
    is the mode's largest over the inputs (its peak in ``B_ij / A`` as a
    share of that pair's)."""
    b_full = [
        [
            np.r_[np.zeros(model.arx.nk), model.numerator(i, j)]
            for j in range(model.n_inputs)
        ]
        for i in range(model.n_outputs)
    ]
    tables = [
        [
            mode_table(
                model.a,
                b,
                model.ts,
                covariance=model.covariance,
                factor=model.covariance_factor,
            )
            for b in row
        ]
        for row in b_full
    ]
    share = np.column_stack(
        [np.nanmax(np.column_stack([t.share for t in row]), axis=1) for row in tables]
    )
    strongest = int(np.argmax(np.nansum(share, axis=0))) if share.size else 0
    best = tables[strongest]
    pick = int(np.argmax([np.nansum(t.share) for t in best]))
    return shared_modes(best[pick], share, model.output_names)


def state_space(model, simo):
    """``(A, B, C, D)``: one SIMO block per input (`simo` of that input's
    numerators over the shared poles, as the single-input model realises
    them), side by side: ``A`` and ``B`` block-diagonal, ``C`` and ``D``
    stacked by columns."""
    nb = model.arx.nb
    blocks = [
        simo(model.a, model.b[:, j * nb : (j + 1) * nb], model.arx, model.integrators)
        for j in range(model.n_inputs)
    ]
    a = block_diag(*[blk[0] for blk in blocks])
    b = block_diag(*[blk[1] for blk in blocks])
    c = np.hstack([blk[2] for blk in blocks])
    d = np.hstack([blk[3] for blk in blocks])
    return a, b, c, d
