"""Several outputs, one denominator: the shared-denominator estimate.

Every sensor of a flexible structure sees the same modes through its own
numerator (:class:`~spiralid.sysid.models.shared.SharedDenominatorModel`).
The simulation error of output ``i`` is linear in its numerator ``b_i``, so
for a candidate denominator each numerator is projected out exactly as for
one output (:class:`~spiralid.sysid.estimation.linear.varpro.ProjectedCost`), and
the outputs' squared errors add up with a weight each:

    J(A) = sum_i lambda_i ||y_i - V(A) b_i(A)||^2.

The spiral search (:func:`~spiralid.sysid.estimation.spiral.projected.projected_spiral`,
Eb-SDA over the modal coordinates of ``A`` with Gauss-Newton polish and
restarts, as the single-output ``"spiral"``) searches ``A`` alone; each
output adds a projection, not a search dimension.

Weights. A first fit weighs each output by its mean square, so that every
sensor counts in its own units' scale (the cost is then the RMS over the
outputs of their percent errors, eq. (2)). Each output's residual variance
``sigma_i^2`` there is its noise level, and the estimate is polished again
with ``lambda_i = 1 / sigma_i^2``, re-estimated from each polish until the
weights settle (within 10 %, at most 5 rounds): the maximum-likelihood
weighting for independent Gaussian sensor noise, so a noisy sensor does not
pull the modes off a clean one's. ``weights=`` gives them explicitly.

Intervals. At the optimum, ``s^2 (J_a' J_a)^-1`` with ``J_a`` the weighted
variable-projection Jacobian (Golub-Pereyra) of every output, stacked, is
the covariance of ``a`` (the numerators' uncertainty is already projected
out), and ``s^2`` the weighted residual variance per degree of freedom.
It comes from the singular values of ``J_a`` with a square-root factor
``R = s S^-1 V^T`` (``C = R^T R``), which the modes' intervals use: the
normal equations ``J_a' J_a`` square the condition of ``J_a`` (about 1e8
on the rig's four outputs at ARX(14, 16, 1)), and from the inverted normal
equations the first mode's delta-method standard error ``sqrt(g' C g)``
came out anywhere between 0 and 1.8 times the factor's ``|R g|`` over 100
noise realisations (one interval of zero width; the factor's varied by
4 %).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from spiralid._checks import generator, integer

from ...data import IOData
from ...models.arx import ARX
from ...models.polynomials import is_stable_polynomial
from ...models.shared import SharedDenominatorModel
from ..linear.margin import AUTO, is_auto, max_radius
from ..linear.modal import ModalParametrization
from ..linear.varpro import ProjectedCost, gauss_newton_polish
from .inputs import (
    SharedInputsCost,
    WeightedOutputs,
    equation_regressors,
    shared_integrators,
    summed,
)

__all__ = [
    "SHARED_METHODS",
    "SharedProjectedCost",
    "identify_shared",
    "joint_least_squares",
]

# The final polishes' budget, in evaluations per searched coordinate (the
# single-output polish runs LM to its tolerances; this is its like).
_POLISH_NFEV = 40
# At most this many rounds of noise weights, each a polish (module docstring).
_REWEIGHTS = 5


def shared_options(method: str) -> tuple[str, ...]:
    """The options `identify` takes with `method` on a record of several
    outputs (one shared denominator)."""
    return ("rng", "predictor", "initial", "integrator", *SHARED_METHODS[method])


class SharedProjectedCost(WeightedOutputs):
    """``J(A)`` over denominators, every output's numerator projected out.

    Parameters
    ----------
    arx : ARX
        Each output's structure, without its known integrators.
    data : IOData
        A record of ``p >= 1`` outputs.
    weights : array_like, shape (p,), optional
        ``lambda_i``; default ``1 / mean(y_i^2)`` (each output in its own
        scale).
    integrators : sequence of int, optional
        Each output's known integrators ``k_i`` (poles at ``z = 1`` outside
        the shared ``A``): output ``i`` is ``B_i / A`` applied to the
        ``k_i``-fold running sum of the input (as a single output's
        ``identify(integrator=k)``); default none.

    The value reported is a percent RMS error:
    ``100 sqrt(J / sum_i lambda_i ||y_i||^2)``, which with the default
    weights is the RMS over the outputs of their percent errors.
    """

    def __init__(self, arx: ARX, data: IOData, weights=None, integrators=None) -> None:
        self.arx = arx
        self.data = data
        self.integrators = shared_integrators(integrators, data.n_outputs)
        self.parts = [
            ProjectedCost(arx, summed(data.output(i), k))
            for i, k in enumerate(self.integrators)
        ]
        self._weigh(weights)

    def normal_equations(self, a):
        total_s, total_g, total_h = 0.0, 0.0, 0.0
        for w, part in zip(self.weights, self.parts, strict=True):
            s, g, h = part.normal_equations(a)
            total_s, total_g, total_h = (
                total_s + w * s,
                total_g + w * g,
                total_h + w * h,
            )
        return total_s, total_g, total_h

    def evaluate(self, a) -> tuple[np.ndarray, np.ndarray]:
        """Costs and numerators ``[b_1, .., b_p]`` of a population."""
        aa = np.atleast_2d(np.asarray(a, dtype=float))
        sse = np.zeros(aa.shape[0])
        numerators = []
        for w, part in zip(self.weights, self.parts, strict=True):
            f, b = part.evaluate(aa)
            # The part's cost back to its squared error (w K / ... scaling).
            sse += w * (f * part.K / part.w) ** 2
            numerators.append(b)
        f = np.array([self.fun_of_sse(s) for s in sse])
        return f, np.concatenate(numerators, axis=1)

    def __call__(self, a):
        aa = np.asarray(a, dtype=float)
        f, _ = self.evaluate(aa)
        return float(f[0]) if aa.ndim == 1 else f

    def per_output(self, a) -> np.ndarray:
        """Each output's own paper cost, eq. (2), at denominator `a`."""
        return np.array([float(part(a)) for part in self.parts])

    def numerators(self, a) -> np.ndarray:
        """``b_i(A)``, shape (p, nb)."""
        return np.array([part.numerator(a) for part in self.parts])


def _coordinates(theta_a, par: ModalParametrization, arx: ARX) -> np.ndarray:
    """A least-squares denominator as modal coordinates: stabilised, inside
    the margin, clipped to the box."""
    from ...models.polynomials import step_up
    from ..linear.margin import project_denominator
    from ..linear.parametrizations import KMAX, stabilise

    theta = stabilise(np.r_[theta_a, np.zeros(arx.nb)], arx)
    a = step_up(theta[: arx.na])
    if par.max_radius is not None:
        a = project_denominator(a, par.max_radius, KMAX)
    box = par.bounds
    return np.clip(par.from_denominator(a), box[:, 0], box[:, 1])


def _subspace_start(cost: SharedProjectedCost, par: ModalParametrization):
    """The subspace (PO-MOESP) poles of every output, in modal coordinates,
    when the outputs share their inputs (the same integrators) and the
    record is long enough; None otherwise."""
    from .subspace import subspace_denominator

    if len(set(cost.integrators)) != 1:
        return None
    summed = cost.parts[0].data.u
    record = replace(cost.data, u=summed)
    try:
        a = subspace_denominator(record, cost.arx.na)
    except (ValueError, np.linalg.LinAlgError):
        return None
    return _coordinates(a, par, cost.arx)


def _starts(cost: SharedProjectedCost, par: ModalParametrization) -> np.ndarray:
    """Each output's least-squares denominator (of its record with the
    input summed for its integrators), in modal coordinates: a sensor's own
    estimate of the shared modes."""
    from ...models.arx import arx_least_squares

    arx = cost.arx
    # Several inputs: each output's least squares over all of them.
    fit = arx_least_squares if cost.data.n_inputs == 1 else _one_joint
    return np.array(
        [_coordinates(fit(part.data, arx)[: arx.na], par, arx) for part in cost.parts]
    )


def _one_joint(one: IOData, arx: ARX) -> np.ndarray:
    return joint_least_squares([one], arx)


# The methods a record of several outputs takes, and the options of each
# (beside rng, predictor and initial, which every one accepts as identify's).
SHARED_METHODS = {
    "spiral": ("max_time_constant", "n_points", "max_nfev", "weights"),
    "oe": ("max_time_constant", "weights"),
    "ls": ("weights",),
}


def identify_shared(
    data: IOData,
    arx: ARX,
    *,
    method: str = "spiral",
    rng=None,
    n_points: int = 50,
    max_nfev: int = 10_000,
    weights=None,
    integrator=0,
    max_time_constant: float | str | None = AUTO,
) -> SharedDenominatorModel:
    """One denominator for every output of `data`.

    Parameters
    ----------
    data : IOData
        A record of ``p >= 2`` outputs (``y`` of shape (N, p)) from rest,
        or of ``m >= 2`` inputs (``u`` of shape (N, m)) and any outputs:
        then every output is ``y_i = sum_j B_ij / A u_j``, all ``p m``
        numerators projected out
        (:class:`~spiralid.sysid.estimation.shared.inputs.SharedInputsCost`).
    arx : ARX
        Each input-output pair's structure: ``na`` shared poles, ``nb``
        numerator coefficients per pair after ``nk`` delays.
    method : {"spiral", "oe", "ls"}
        ``"spiral"``: the spiral search over the shared modes (Eb-SDA over
        the modal coordinates, Gauss-Newton polish every 5 iterations,
        restarts after 20 stalled ones, first points at each output's
        least-squares denominator), its best then polished beside output
        error's starts and the lowest cost kept, so it never ends above
        output error. ``"oe"``: output error, the same polish from each
        output's least-squares denominator, the joint least-squares one and
        the subspace poles
        (:func:`~spiralid.sysid.estimation.shared.subspace.subspace_denominator`,
        when every output has the same integrators), the lowest cost kept
        (no search).
        ``"ls"``: least squares of the equation error of every output with
        one ``A`` (the joint ARX estimate; its poles may be unstable).
    rng : int, Generator or None
        Seeds the search.
    n_points, max_nfev : int
        The search's population and budget of joint-cost evaluations.
    weights : array_like, shape (p,), optional
        ``lambda_i`` of the joint cost; default estimated: a first fit in
        each output's scale, then ``1 / sigma_i^2`` from its residuals
        (module docstring).
    integrator : int or sequence of int
        Known integrators (poles at ``z = 1``) of every output, or of each:
        ``(2, 1, 0, 0)`` for the rig's hub angle, hub velocity, end-point
        acceleration and tip deflection. They are outside the shared ``A``:
        ``arx.na`` counts the shared poles only.
    max_time_constant : float, "auto" or None
        The stability margin, as :func:`~spiralid.sysid.identify`'s:
        ``"auto"`` keeps every pole's time constant within the record.

    Returns
    -------
    SharedDenominatorModel
    """
    t0 = time.perf_counter()
    if not isinstance(data, IOData):
        raise TypeError(f"`data` must be an IOData; got {type(data).__name__}")
    if getattr(arx, "family", None) != "arx" or arx.na < 1:
        raise ValueError(f"`arx` must be an ARX with na >= 1; got {arx!r}")
    if method not in SHARED_METHODS:
        raise ValueError(
            f"`method` must be one of {tuple(SHARED_METHODS)} for several outputs; "
            f"got {method!r}"
        )
    n_points = integer(n_points, "n_points", 2)
    max_nfev = integer(max_nfev, "max_nfev", n_points)
    several = SharedInputsCost if data.n_inputs > 1 else SharedProjectedCost
    first = several(arx, data, weights, integrator)
    if method == "ls":
        theta = joint_least_squares(_parts_record(first), arx, first.weights)
        a = theta[: arx.na]
        b = theta[arx.na :].reshape(data.n_outputs, data.n_inputs * arx.nb)
        return _model(data, arx, "ls", first, a, b, None, {}, t0)
    par = ModalParametrization(
        arx.na, data.ts, max_radius=_radius(data, max_time_constant)
    )
    starts = _starts(first, par)
    joint = joint_least_squares(_parts_record(first), arx, first.weights)
    # Output error: the polish from each output's and the joint least-squares
    # denominators and the subspace poles. The search adds its own best to
    # them, so it never ends above output error (the single-output
    # "spiral"'s safe start).
    points = [*starts, _coordinates(joint[: arx.na], par, arx)]
    subspace = _subspace_start(first, par)
    if subspace is not None:
        points.append(subspace)
    result = {
        "message": "Output error from each output's and the joint "
        "least-squares denominators and the subspace poles; the lowest cost "
        "kept."
    }
    if method == "spiral":
        raw = _search(first, par, starts, n_points, max_nfev, rng)
        points.insert(0, raw.z)
        result = {
            "nfev": int(raw.nfev),
            "nit": int(raw.nit),
            "n_restarts": int(raw.n_restarts),
            "message": f"{raw.message} Then polished beside output error from "
            "the least-squares denominators; the lowest cost kept.",
        }
    budget = _POLISH_NFEV * (arx.na + 1)
    polished = [gauss_newton_polish(first, par, x, budget) for x in points]
    z = min(polished, key=lambda r: r.fun).x
    cost, z = _weighted_polish(first, par, z, data, arx, weights is None)
    a = par.to_denominator(z)
    cov = _covariance(cost, a, data, arx)
    return _model(data, arx, method, cost, a, cost.numerators(a), cov, result, t0)


def _radius(data: IOData, max_time_constant) -> float | None:
    if is_auto(max_time_constant):
        return max_radius(data.ts, data.n * data.ts)
    if max_time_constant is None:
        return None
    return max_radius(data.ts, float(max_time_constant))


def _search(cost, par, starts, n_points, max_nfev, rng):
    """The spiral search over the shared modes (the single-output
    ``"spiral"``'s settings)."""
    from spiralid.optim.restarts import Restarts

    from ..spiral.projected import projected_spiral

    return projected_spiral(
        cost,
        par,
        "ebsda",
        n_points=n_points,
        max_nfev=max_nfev,
        polish_every=5,
        polish_nfev=10,
        restarts=Restarts(growth=1, stall=20),
        x0=starts,
        rng=generator(rng),
    )


def _weighted_polish(first, par, z, data, arx, reweight: bool):
    """The noise weights re-estimated at `z` and the fit polished again
    until they settle; the cost used last and the coordinates."""
    budget = _POLISH_NFEV * (arx.na + 1)
    cost = first
    for _ in range(_REWEIGHTS if reweight else 0):
        # Each output's residual variance at the current fit is its noise
        # level; the misfit the first weighting left inflates it, so the
        # weights are re-estimated until they settle.
        a = par.to_denominator(z)
        sigma2 = np.array([part.sse(a) for part in first.parts]) / data.n
        new = 1.0 / np.maximum(sigma2, 1e-300)
        settled = cost is not first and np.allclose(new, cost.weights, rtol=0.1)
        cost = cost.reweighted(new)
        z = gauss_newton_polish(cost, par, z, budget).x
        if settled:
            break
    return cost, z


def _model(data, arx, method, cost, a, b, covariance, result, t0):
    """The model; `covariance` is ``(C, R)`` or None. Its wall time goes
    to ``timings`` as every fitted model's does, not to ``result``."""
    from .covariance import parameter_factor

    covariance, root = (None, None) if covariance is None else covariance
    # Least squares' poles may be unstable: no simulation cost then.
    stable = is_stable_polynomial(a)
    return SharedDenominatorModel(
        a=a,
        b=b,
        arx=arx,
        ts=data.ts,
        output_names=data.output_names,
        output_units=data.output_units,
        input_name=data.input_name,
        input_unit=data.input_unit,
        u_offset=data.u_offset,
        input_names=data.input_names,
        input_units=data.input_units,
        u_offsets=data.u_offsets,
        y_offsets=data.y_offsets,
        method=method,
        cost=float(cost(a)) if stable else float("nan"),
        weights=cost.weights,
        costs=cost.per_output(a) if stable else None,
        covariance=covariance,
        covariance_factor=root,
        integrators=cost.integrators,
        result=result,
        shape_factor=None if covariance is None else parameter_factor(cost, a, b),
        timings={"total": time.perf_counter() - t0},
    )


def _parts_record(cost: SharedProjectedCost) -> list[IOData]:
    """Each output's record as its part of `cost` sees it (the input summed
    for its integrators)."""
    return [part.data for part in cost.parts]


def joint_least_squares(data, arx: ARX, weights=None) -> np.ndarray:
    """``[a, b_1, .., b_p]``: least squares of every output's equation error
    ``y_i(t) + sum_k a_k y_i(t-k) - sum_j b_ij u(t-nk-j)`` with one ``a``,
    each output's rows weighted by ``sqrt(lambda_i)``. `data` is a record
    of several outputs, or a list of single-output records (one per output,
    each with its own input). With several inputs ``b_i`` is ``[b_i1, ..,
    b_im]``, one numerator per input.

    Examples
    --------
    >>> import numpy as np
    >>> from scipy.signal import lfilter
    >>> u = np.random.default_rng(0).standard_normal(400)
    >>> y = np.column_stack([lfilter([0, 1.0], [1, -0.5], u),
    ...                      lfilter([0, 2.0, 1.0], [1, -0.5], u)])
    >>> theta = joint_least_squares(IOData(u, y, ts=1.0), ARX(1, 2, 1))
    >>> (np.round(theta, 9) + 0.0).tolist()   # + 0.0: the zero may round to -0.0
    [-0.5, 1.0, 0.0, 2.0, 1.0]
    """
    records = (
        [data.output(i) for i in range(data.n_outputs)]
        if isinstance(data, IOData)
        else list(data)
    )
    p = len(records)
    weights = np.ones(p) if weights is None else np.asarray(weights, dtype=float)
    # Several inputs: each output's numerators, input by input.
    nb = records[0].n_inputs * arx.nb
    blocks, rhs = [], []
    for i, one in enumerate(records):
        phi = (
            arx.regressors(one)[arx.max_lag :]
            if one.n_inputs == 1
            else equation_regressors(one, arx)
        )
        w = np.sqrt(weights[i])
        row = np.zeros((phi.shape[0], arx.na + p * nb))
        row[:, : arx.na] = phi[:, : arx.na]
        row[:, arx.na + i * nb : arx.na + (i + 1) * nb] = phi[:, arx.na :]
        blocks.append(w * row)
        rhs.append(w * one.y[arx.max_lag :])
    return np.linalg.lstsq(np.vstack(blocks), np.concatenate(rhs), rcond=None)[0]


def _covariance(cost: SharedProjectedCost, a, data: IOData, arx: ARX):
    """``(C, R)``: ``C = s^2 (J_a' J_a)^-1`` of the weighted projected
    residual at `a`, every output's stacked, and its factor ``R = s S^-1
    V^T`` from the SVD ``J_a = U S V^T`` (module docstring); None where
    `a` is unstable, the record too short or ``J_a`` singular (a singular
    value below ``1e-12`` of the largest)."""
    if not is_stable_polynomial(a):
        return None
    dof = data.n * data.n_outputs - arx.na - data.n_outputs * data.n_inputs * arx.nb
    if dof <= 0:
        return None
    rows, residual = [], []
    for w, part in zip(np.sqrt(cost.weights), cost.parts, strict=True):
        r, jac = part.residual(a)
        residual.append(w * r)
        rows.append(w * np.asarray(jac, dtype=float))
    r = np.concatenate(residual)
    s2 = float(r @ r) / dof
    try:
        _, sv, vt = np.linalg.svd(np.vstack(rows), full_matrices=False)
    except np.linalg.LinAlgError:
        return None
    if not sv[-1] > 1e-12 * sv[0]:
        return None
    root = np.sqrt(s2) * vt / sv[:, None]
    return root.T @ root, root
