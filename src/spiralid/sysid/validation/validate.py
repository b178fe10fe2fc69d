"""Model validation the way the paper and MATLAB's toolbox judge a model.

:func:`validate` applies the measured input of a validation record to any
fitted model, linear or not, and reports, in one :class:`Validation`:

* time domain: fit % as MATLAB's ``compare`` defines it, RMSE, the paper's
  cost (eq. (2)-(3)) and the range of the error (the paper's Table-2), for
  the free-run simulation (the paper's validation, Figure-3) and, labelled
  separately, the one-step prediction;
* residual analysis: whiteness of the residual and its independence from the
  input, with 95 % and 99 % bands (:mod:`spiralid.sysid.validation.correlation`);
* frequency domain: Welch spectra of measured and modelled output and their
  resonance peaks (:mod:`spiralid.sysid.spectra`; the paper's Figure-7c);
* for a linear model (:mod:`.linear`): the model's own modes from its poles,
  stability from the poles, and controllability / observability of its
  state-space realisation (the paper's MATLAB ``ctrb``/``obsv`` check after
  eq. (10));
* for a nonlinear model (:mod:`.nonlinear`): the Billings-Voon higher-order
  correlation tests and what the network added over its linear start.

The shared part is computed once, by one code path, for every structure;
then the linear or the nonlinear extras.
"""

from __future__ import annotations

import numpy as np

from spiralid._checks import one_of, refuse_options

from ..estimation.core.cost import cost_of_errors
from ..models.protocol import check_fitted
from ..signals import check_pair
from ..spectra import find_resonances, psd
from .correlation import (
    check_lags,
    independence_test,
    whiteness_test,
)
from .fit import (
    _bounded_run,
    _gain,
    _signals_of,
    check_sample_time,
    fit_from_measured,
    fit_percent,
    responses,
    rmse,
)
from .inputs import validate_inputs
from .linear import absent, linear_checks, runaway_note
from .nonlinear import nonlinear_checks
from .outputs import check_output_records, joint_fit
from .realization import Realization, realization_tests
from .result import Validation

__all__ = [
    "Realization",
    "Validation",
    "fit_percent",
    "realization_tests",
    "rmse",
    "validate",
]

_RESIDUALS = ("one-step", "simulation")


def validate(
    model,
    data,
    *,
    lags: int = 25,
    n_peaks: int = 3,
    levels=(0.95, 0.99),
    residuals: str = "auto",
    nperseg: int | None = None,
    max_damping: float = 0.3,
    gain="auto",
    warmup=None,
    label: str | None = None,
) -> Validation:
    """Validate an identified model on a record (the paper's validation phase).

    Parameters
    ----------
    model : FittedModelProtocol
        From :func:`~spiralid.sysid.identify` or
        :func:`~spiralid.sysid.load_model`, of any family (it implements
        :class:`~spiralid.sysid.models.protocol.FittedModelProtocol`): a
        linear model (ARX) or a nonlinear one (``is_linear`` false: NARX,
        polynomial NARX). Every model gets the same :class:`Validation`; a
        linear model's has its poles, modes and realisation tests, a
        nonlinear model's its ``nonlinear`` part (the Billings-Voon tests,
        the network's gain over its linear start). `max_damping` (modes
        from poles) does not apply to a nonlinear model: a value other than
        its default is refused in one line. A model of several outputs
        (:class:`~spiralid.sysid.SharedDenominatorModel`) is validated
        output by output (``model.output_model(name)`` on ``data.output(name)``,
        with every option here): its :class:`Validation` holds each
        output's in ``outputs``, the joint fit as ``fit_percent``
        (:func:`~spiralid.sysid.validation.outputs.joint_fit`) and the
        model's modes as ``mode_table``. A model of several inputs is
        validated output by output from all its inputs
        (:func:`~spiralid.sysid.validation.inputs.validate_inputs`: fits,
        errors, spectra and whiteness; no test of independence from one
        input).
    data : IOData
        The validation record, usually the last third (the paper's split);
        for a model of several outputs, a record holding each of them by
        name.
        The model is run from zero initial conditions over it.
    lags : int, default 25
        Correlation lags: autocorrelation at ``1..lags``, cross-correlation at
        ``-lags..lags``; ``1 <= lags < N``.
    n_peaks : int, default 3
        Resonance peaks to find in each spectrum (three modes in 0-100 Hz for
        the paper's arm).
    levels : sequence of float, default (0.95, 0.99)
        Confidence levels of the correlation bands and verdicts.
    residuals : {"auto", "one-step", "simulation"}, default "auto"
        Which error the correlation tests examine. ``"auto"`` takes the error
        the model was fitted to: the one-step prediction error for least
        squares and one-step searches (the ARX model's estimate of its
        innovations, which MATLAB's ``resid`` tests, and which it promises
        white and independent of the input), the simulation error for output
        error and the simulation searches. Such an output-error model
        promises only that its simulation error is independent of past
        inputs; it does not model the noise, so the whiteness test is then
        reported as not applicable (``Validation.output_error``).
    nperseg : int, optional
        Welch segment length; default :func:`~spiralid.sysid.spectra.default_nperseg`.
    max_damping : float, default 0.3
        Model modes with a damping ratio below this are listed.
    gain : "auto", "model" or float, default "auto"
        Gain ``w`` of the paper's cost on this record. ``"auto"`` recomputes
        it on ``data`` (``w = 100 sqrt(K) / rms(y)``), so the cost is
        ``100 rms(e) / rms(y)``, a percentage comparable between records.
        ``"model"`` reuses the model's own ``w`` (fixed on the estimation
        record, so on another record the cost is scaled by
        ``sqrt(K_est / K) rms(y_est) / rms(y)``); a number is used as given.
    warmup : IOData, optional
        The record that immediately precedes ``data`` (typically the
        estimation part). The model is run over it first and only the
        ``data`` part is scored, so the validation starts from the state the
        model has reached rather than from rest. Default: zero initial
        conditions, as the paper applies the input to the model.
    label : str, optional
        Name for tables and legends; default the model's ``method``.

    Returns
    -------
    Validation
        One type for every model, of one output or several (see
        :class:`Validation`).

    Raises
    ------
    ValueError
        ``lags`` outside ``[1, N - 1]``, unknown ``residuals``, mismatched
        signal lengths, or a sample time of the data that differs from the
        model's.

    Examples
    --------
    A noise-free ARX(2, 2, 1) record: least squares recovers the system, and
    the validation part is reproduced exactly.

    >>> import numpy as np
    >>> from scipy import signal
    >>> from spiralid.sysid import ARX, IOData, identify
    >>> u = np.random.default_rng(0).standard_normal(600)
    >>> y = signal.lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u)
    >>> est, val = IOData(u, y, ts=0.01).split(2 / 3)
    >>> fit = identify(est, ARX(2, 2, 1), method="ls")
    >>> rep = validate(fit, val, warmup=est, max_damping=1.0)
    >>> round(rep.fit_percent, 6), rep.stable, rep.realization.minimal
    (100.0, True, True)

    The pole pair of ``1 - 1.5 z^-1 + 0.7 z^-2`` is a mode at 7.84 Hz with
    damping 0.36 (listed because ``max_damping`` was raised from 0.3):

    >>> np.round(rep.modes.frequency, 2), np.round(rep.modes.damping, 2)
    (array([7.84]), array([0.36]))

    Notes
    -----
    The cost is eq. (2)-(3), ``w sqrt(sum e^2) / K`` plus the model's penalty
    when a pole has ``|z| >= 1``, with ``e`` the error of the model's own
    predictor (``model.predictor``) computed exactly as for the fit and error
    range (zero initial conditions, or after ``warmup``). It therefore equals
    ``100 rms(e) / rms(y)`` with ``gain="auto"``. For a simulation-predictor
    model estimated with ``initial="rest"`` (the default) and no ``warmup``
    this is exactly :class:`~spiralid.sysid.PaperCost` with
    ``initial="rest"`` on ``data``, the criterion the model was fitted with.
    The validation run always starts from rest (or after ``warmup``),
    whatever the model's ``initial``: a model estimated with
    ``initial="measured"`` (for records that start in motion) is scored on
    the same free run as its fit and error range, so its cost here can
    differ from ``PaperCost(..., initial="measured")`` on the same record,
    a lot for poles close to the unit circle, whose start-up transient
    hardly decays. Pass ``warmup`` to validate such a model from the state
    it has reached.
    """
    options = dict(
        lags=lags,
        n_peaks=n_peaks,
        levels=levels,
        residuals=residuals,
        nperseg=nperseg,
        max_damping=max_damping,
        gain=gain,
    )
    check_fitted(model)
    if getattr(model, "n_inputs", 1) > 1:
        return validate_inputs(model, data, warmup, label, options)
    names = tuple(model.output_names)
    if len(names) > 1 or model.output_model(names[0]) is not model:
        return _validate_outputs(model, data, warmup, label, options)
    linear = bool(model.is_linear)
    if not linear:
        # Modes are read from poles, which a nonlinear model does not have:
        # the option is refused rather than ignored.
        refuse_options(
            dict(max_damping=max_damping),
            (
                "lags", "n_peaks", "levels", "residuals", "nperseg", "gain",
                "warmup", "label",
            ),
            "validate for a nonlinear model",
            defaults=dict(max_damping=0.3),
        )  # fmt: skip
    if isinstance(residuals, str) and residuals == "auto":
        residuals = _fitted_error(model)
    u, y, ts, lags, predictor = _valid_inputs(model, data, lags, residuals)
    extras = linear_checks(model, ts, max_damping) if linear else absent()

    # The shared part, the same for every structure.
    n = y.size
    w = _gain(gain, model, y)
    penalty = float(getattr(model, "penalty", 1e6))
    with np.errstate(all="ignore"):  # a diverging free run is reported below
        y_sim, y_pred, start = responses(model, data, warmup)
    y_sim, diverged = _bounded_run(y_sim, y, runaway_note(extras))
    y, y_pred = check_pair(y, y_pred, "data.y", "model.predict(data)")
    e_sim, e_pred = y - y_sim, y - y_pred

    # Eq. (2)-(3) on the very errors the fit and error range are computed
    # from, so the columns of a Table-2 row agree with one another. A
    # nonlinear model has no poles to penalise: its free run is its verdict.
    e_cost = e_sim if predictor == "simulation" else e_pred
    stable = extras["stable"] is not False
    cost = cost_of_errors(e_cost, w, stable, penalty)

    e_test = e_pred if residuals == "one-step" else e_sim
    fs = 1.0 / ts
    spec_y = psd(y, fs, nperseg=nperseg)
    spec_m = psd(y_sim, fs, nperseg=nperseg)
    label = label if label is not None else str(getattr(model, "method", "") or "")

    nonlinear = None
    if not linear:
        whole = u if warmup is None else np.r_[_signals_of(warmup, "warmup")[0], u]
        nonlinear = nonlinear_checks(model, u, e_test, y, whole, start, lags, levels)

    return Validation(
        label=label,
        n_samples=n,
        ts=ts,
        fit_percent=fit_percent(y, y_sim),
        fit_percent_one_step=fit_percent(y, y_pred),
        rmse=rmse(y, y_sim),
        rmse_one_step=rmse(y, y_pred),
        cost=float(cost),
        cost_predictor=predictor,
        error_range=(float(e_sim.min()), float(e_sim.max())),
        error_range_one_step=(float(e_pred.min()), float(e_pred.max())),
        residuals=residuals,
        whiteness=whiteness_test(e_test, lags, levels),
        independence=independence_test(u, e_test, lags, levels),
        psd_measured=spec_y,
        psd_model=spec_m,
        peaks_measured=find_resonances(spec_y, n_peaks),
        peaks_model=find_resonances(spec_m, n_peaks),
        t=(np.arange(n) + start) * ts,
        u=u,
        y=y,
        y_sim=y_sim,
        y_pred=y_pred,
        output_name=str(getattr(data, "output_name", "output")),
        output_unit=str(getattr(data, "output_unit", "")),
        initial="rest" if warmup is None else "warmup",
        fit_percent_measured=fit_from_measured(model, data),
        diverged=diverged,
        output_error=_fitted_error(model) == "simulation",
        choice=_choice_notes(model),
        nonlinear=nonlinear,
        **extras,
    )


def _validate_outputs(model, data, warmup, label, options: dict) -> Validation:
    """`validate` of a model of several outputs: each output's model on
    that output of the records, and their joint fit."""
    check_output_records(model, data, warmup)
    label = model.method if label is None else str(label)
    outputs = {
        name: validate(
            model.output_model(name),
            data.output(name),
            warmup=None if warmup is None else warmup.output(name),
            label=f"{label}, {name}",
            **options,
        )
        for name in model.output_names
    }
    return Validation(
        label=label,
        fit_percent=joint_fit([v.fit_percent for v in outputs.values()]),
        mode_table=model.modes if model.is_linear else None,
        outputs=outputs,
        mode_shapes=getattr(model, "shapes", None),
    )


def _choice_notes(model) -> str | None:
    """What the estimate's held-back choices said (among minima, and of the
    stability margin), in words; None when it made neither."""
    notes = [
        record["note"]
        for record in (
            getattr(model, "selection", None),
            getattr(model, "margin", None),
            getattr(model, "diagnosis", None),
        )
        if record
    ]
    return ". Then ".join(notes) or None


def _fitted_error(model) -> str:
    """The error `model`'s estimate minimised: its method's (least squares:
    the one-step error), else the predictor its cost used."""
    from ..estimation.core.estimators import METHODS

    method = METHODS.get(str(getattr(model, "method", "")))
    predictor = getattr(model, "predictor", None) or "simulation"
    return (method.minimises if method is not None else None) or predictor


def _valid_inputs(model, data, lags, residuals):
    """`validate`'s argument checks: the signals, ``lags`` and the predictor,
    before any simulation or spectrum is computed."""
    u, y, ts = _signals_of(data)
    # Checked here too (the correlation tests would) so a bad `lags` fails
    # before the simulation and spectra are computed.
    lags = check_lags(lags, y.size)
    structure = model.structure
    if structure.max_lag >= y.size:
        # Before any signal of that length is built (a tampered file's nk
        # could ask for terabytes).
        raise ValueError(
            f"`model` reaches {structure.max_lag} samples into the past "
            f"({structure}), more than `data`'s N = {y.size} samples hold"
        )
    if residuals not in _RESIDUALS:
        raise ValueError(
            f"`residuals` must be 'auto' or one of {_RESIDUALS}; got {residuals!r}"
        )
    check_sample_time(model, ts)
    predictor = getattr(model, "predictor", None) or "simulation"
    one_of(predictor, "model.predictor", _RESIDUALS)
    return u, y, ts, lags, predictor
