"""Validation of a model of several inputs (a shared denominator over every
input-output pair): each output's free run and one-step prediction from
all the inputs, in the one :class:`~spiralid.sysid.validation.result.Validation`.

Each output is the sum of its inputs' responses, so it has no
single-input model to validate alone (as a model of several outputs of one
input has, ``model.output_model(name)``). Each output's entry holds what
does not assume one input: the fits, RMS errors, error ranges and cost of
the free run and of the one-step prediction, both spectra and their peaks,
and the whiteness of the simulation error (which an output-error model
does not promise: reported, as for one input, as not applicable). The test
of independence from the input is made against each input and the least
independent kept (the smallest p-value: an output-error model promises
independence from every input). The zeros and the realisation tests are
left out (empty, None): each pair ``B_ij / A`` has its own.
"""

from __future__ import annotations

import numpy as np

from ..data import IOData
from ..spectra import find_resonances, modes_from_poles, psd
from .correlation import independence_test, whiteness_test
from .fit import fit_percent, rmse
from .outputs import check_output_records, joint_fit
from .result import Validation

__all__ = ["validate_inputs"]


def _check_inputs(model, record, name: str) -> None:
    if record is not None and record.n_inputs != model.n_inputs:
        raise ValueError(
            f"`{name}` must hold the model's {model.n_inputs} inputs "
            f"{model.input_names}; got {record.n_inputs}"
        )


def _joined(warmup: IOData | None, data: IOData) -> tuple[IOData, int]:
    """The record the model runs over (the warm-up, then `data`) and where
    `data` starts in it."""
    if warmup is None:
        return data, 0
    names = data.output_names
    whole = IOData(
        np.r_[warmup.inputs, data.inputs],
        np.r_[warmup.select_outputs(names).outputs, data.select_outputs(names).outputs],
        ts=data.ts,
        input_name=data.input_names,
        output_name=names if len(names) > 1 else names[0],
    )
    return whole, warmup.n


def validate_inputs(model, data, warmup, label, options: dict) -> Validation:
    """:func:`~spiralid.sysid.validate` of a model of several inputs: each
    output's fits from every input (module docstring) and their joint fit.

    Parameters
    ----------
    model : SharedDenominatorModel
        A model of ``m >= 2`` inputs.
    data, warmup : IOData
        The validation record and the one before it (None: from rest),
        holding the model's outputs by name and its inputs in order.
    label : str or None
        The validation's label (default the model's method).
    options : dict
        ``validate``'s options; ``lags``, ``levels``, ``n_peaks``,
        ``nperseg`` and ``max_damping`` apply.
    """
    check_output_records(model, data, warmup)
    _check_inputs(model, data, "data")
    _check_inputs(model, warmup, "warmup")
    label = model.method if label is None else str(label)
    whole, start = _joined(warmup, data)
    with np.errstate(all="ignore"):
        y_sim = model.simulate(whole.inputs)[start:]
        y_pred = model.predict(whole)[start:]
    fs = 1.0 / data.ts
    nperseg, lags, levels = options["nperseg"], options["lags"], options["levels"]
    outputs = {}
    for i, name in enumerate(model.output_names):
        one = data.output(name)
        y, sim, pred = one.y, y_sim[:, i], y_pred[:, i]
        e_sim, e_pred = y - sim, y - pred
        spec_y, spec_m = psd(y, fs, nperseg=nperseg), psd(sim, fs, nperseg=nperseg)
        outputs[name] = Validation(
            label=f"{label}, {name}",
            n_samples=one.n,
            ts=one.ts,
            fit_percent=fit_percent(y, sim),
            fit_percent_one_step=fit_percent(y, pred),
            rmse=rmse(y, sim),
            rmse_one_step=rmse(y, pred),
            cost=100.0 * rmse(y, sim) / float(np.sqrt(np.mean(y * y))),
            cost_predictor="simulation",
            error_range=(float(e_sim.min()), float(e_sim.max())),
            error_range_one_step=(float(e_pred.min()), float(e_pred.max())),
            residuals="simulation",
            whiteness=whiteness_test(e_sim, lags, levels),
            independence=min(
                (independence_test(u, e_sim, lags, levels) for u in data.inputs.T),
                key=lambda test: test.p_value,
            ),
            psd_measured=spec_y,
            psd_model=spec_m,
            peaks_measured=find_resonances(spec_y, options["n_peaks"]),
            peaks_model=find_resonances(spec_m, options["n_peaks"]),
            modes=modes_from_poles(
                model.poles, one.ts, max_damping=options["max_damping"]
            ),
            zeros=np.zeros(0, complex),
            stable=model.is_stable,
            max_pole_radius=model.max_pole_radius,
            poles=model.poles,
            t=(np.arange(one.n) + start) * one.ts,
            y=y,
            y_sim=sim,
            y_pred=pred,
            output_name=name,
            output_unit=one.output_unit,
            initial="rest" if warmup is None else "warmup",
            output_error=True,
        )
    return Validation(
        label=label,
        fit_percent=joint_fit([v.fit_percent for v in outputs.values()]),
        mode_table=model.modes,
        outputs=outputs,
    )
