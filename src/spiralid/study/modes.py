"""The simulated rig's modes from every sensor of one run.

The paper identifies its model from one sensor (the end-point acceleration).
The rig records four, all driven by the one hub torque and sharing the
structure's modes: :func:`fit_every_sensor` identifies one denominator for
all of them (:data:`RIG_OUTPUTS`, :data:`SHARED_ARX` with each sensor's known
integrators :data:`RIG_INTEGRATORS`) and sets its modes against the rig's
finite-element model as a :class:`SharedModesFit`. Both
``spiralid reproduce --all-outputs`` and a study's rig record with
``all_outputs = true`` call it, so the two report the same fit.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from spiralid.sysid import (
    ARX,
    IOData,
    SharedDenominatorModel,
    Validation,
    identify,
    validate,
)

__all__ = [
    "MODE_WINDOW",
    "RIG_INTEGRATORS",
    "RIG_OUTPUTS",
    "SHARED_ARX",
    "SharedModesFit",
    "fit_every_sensor",
    "fit_percents",
    "modes_comparison",
    "rig_record",
]

# Every sensor of the simulated rig's experiment, each one's known
# integrators against the hub torque (the hub angle twice, the hub velocity
# once, outside the shared poles) and the structure that identifies the
# shared modes from all four: three modes, the anti-aliasing filter's pair
# and the fourth mode (docs/results/identification.md, "Several sensors").
RIG_OUTPUTS = ("hub_angle", "hub_velocity", "end_acceleration", "tip_deflection")
RIG_INTEGRATORS = (2, 1, 0, 0)
SHARED_ARX = ARX(10, 10, 1)
# The FEM modes the shared fit is set against.
_FEM_MODES = 3
# A model's mode stands for a FEM mode when within this share of its
# frequency: a model that lacks a mode is not credited with a neighbour's.
MODE_WINDOW = 0.10
_PARTS = ("estimation", "validation")


def fit_percents(estimation: Validation, validation: Validation) -> dict:
    """Each output's free-run fit (%) and the joint fit on the two parts.

    Parameters
    ----------
    estimation, validation : Validation
        :func:`~spiralid.sysid.validate` on the two parts (each output's
        and the joint fit).

    Returns
    -------
    dict
        Per part (``"estimation"``, ``"validation"``): ``"outputs"`` (output
        name to fit %), ``"joint"`` (the joint fit %) and ``"diverged"`` (the
        outputs whose free run diverged).
    """
    return {
        part: {
            "outputs": {n: float(v.fit_percent) for n, v in ov.outputs.items()},
            "joint": float(ov.fit_percent),
            "diverged": [n for n, v in ov.outputs.items() if v.diverged],
        }
        for part, ov in zip(_PARTS, (estimation, validation), strict=True)
    }


@dataclass
class SharedModesFit:
    """The rig's modes identified from every sensor of the experiment.

    One denominator for the hub angle, hub velocity, end-point acceleration
    and tip deflection of one simulated run (:data:`RIG_OUTPUTS`,
    :data:`SHARED_ARX`, :data:`RIG_INTEGRATORS`), by
    :func:`~spiralid.sysid.identify`'s default method, beside the paper's
    single-output models.

    Attributes
    ----------
    model : SharedDenominatorModel
    estimation, validation : Validation or None
        Each output's fit and the joint fit on the two parts; None for a
        fit read back from a study's store (:meth:`from_dict`), which keeps
        their numbers in `fits`.
    fem_hz : ndarray, shape (3,)
        The rig's first three natural frequencies from its finite-element
        model (``FlexibleManipulator(...).modes(3)`` of the rig simulated),
        Hz.
    seed : int
        The search's seed.
    seconds : float
        Wall time of the identification.
    fits : dict
        :func:`fit_percents` of `estimation` and `validation` (filled from
        them when not given).
    """

    model: SharedDenominatorModel
    estimation: Validation | None
    validation: Validation | None
    fem_hz: np.ndarray
    seed: int
    seconds: float
    fits: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.fem_hz = np.asarray(self.fem_hz, dtype=float)
        if not self.fits:
            if self.estimation is None or self.validation is None:
                raise ValueError(
                    "`fits` must be given when `estimation` or `validation` is None"
                )
            self.fits = fit_percents(self.estimation, self.validation)

    def nearest(self, frequencies) -> tuple[np.ndarray, np.ndarray]:
        """For each FEM mode, the nearest of `frequencies` (Hz) and its
        error in percent of the FEM's; NaN when none is within
        :data:`MODE_WINDOW` of it (the model has not found that mode).

        Parameters
        ----------
        frequencies : array_like
            A model's mode frequencies, Hz.
        """
        return _nearest(self.fem_hz, frequencies)

    def to_dict(self) -> dict:
        """A JSON-safe form; :meth:`from_dict` reads it back."""
        hz, err = self.nearest(self.model.modes.table.frequency)
        return {
            "outputs": list(self.model.output_names),
            "structure": {
                "na": self.model.arx.na,
                "nb": self.model.arx.nb,
                "nk": self.model.arx.nk,
            },
            "integrators": list(self.model.integrators),
            "method": self.model.method,
            "seed": self.seed,
            "seconds": self.seconds,
            "fem_modes_hz": self.fem_hz.tolist(),
            "nearest_modes_hz": plain_list(hz),
            "error_percent": plain_list(err),
            "modes": self.model.modes.to_dict(),
            "fit_percent": {
                part: {**self.fits[part]["outputs"], "joint": self.fits[part]["joint"]}
                for part in _PARTS
            },
            "diverged": {part: self.fits[part]["diverged"] for part in _PARTS},
            "model": self.model.to_dict(),
        }

    @classmethod
    def from_dict(cls, d: dict) -> SharedModesFit:
        """The fit :meth:`to_dict` wrote, its validations as numbers only.

        Parameters
        ----------
        d : dict
            :meth:`to_dict`'s output.
        """
        fits = {}
        for part in _PARTS:
            numbers = dict(d["fit_percent"][part])
            joint = numbers.pop("joint")
            fits[part] = {
                "outputs": numbers,
                "joint": joint,
                "diverged": list(d.get("diverged", {}).get(part, [])),
            }
        return cls(
            model=SharedDenominatorModel.from_dict(d["model"]),
            estimation=None,
            validation=None,
            fem_hz=np.asarray(d["fem_modes_hz"], dtype=float),
            seed=int(d["seed"]),
            seconds=float(d["seconds"]),
            fits=fits,
        )


def _nearest(reference, frequencies) -> tuple[np.ndarray, np.ndarray]:
    """Each `reference` frequency's nearest in `frequencies` and its error
    (% of the reference); NaN where none is within :data:`MODE_WINDOW`."""
    ref = np.asarray(reference, dtype=float)
    f = np.asarray(frequencies, dtype=float)
    f = f[np.isfinite(f)]
    if f.size == 0:
        nan = np.full(ref.shape, np.nan)
        return nan, nan.copy()
    hz = f[np.argmin(np.abs(f[None, :] - ref[:, None]), axis=1)]
    err = 100.0 * (hz - ref) / ref
    far = np.abs(err) > 100.0 * MODE_WINDOW
    hz[far], err[far] = np.nan, np.nan
    return hz, err


def plain_list(values) -> list:
    """`values` as floats for JSON, None where not finite.

    Parameters
    ----------
    values : array_like
    """
    return [float(v) if np.isfinite(v) else None for v in values]


def modes_comparison(fit: SharedModesFit, models) -> list[dict]:
    """The FEM's modes beside those of the shared fit and of other models.

    Parameters
    ----------
    fit : SharedModesFit
    models : iterable of (str, model, ARX)
        Each single-output model beside the shared fit, with its label and
        structure (an :class:`~spiralid.sysid.IdentifiedModel`, or anything
        whose ``modes`` is a mode table).

    Returns
    -------
    list of dict
        The shared fit first, then each of `models`: ``model`` (its label),
        ``structure``, and for each FEM mode the model's nearest mode
        (``frequency_hz``) and its error in percent (``error_percent``);
        None where the model has none within :data:`MODE_WINDOW`.
    """
    rows = []
    for label, model, arx in [("every sensor", fit.model, fit.model.arx), *models]:
        table = getattr(model.modes, "table", model.modes)
        hz, err = fit.nearest(table.frequency)
        rows.append(
            {
                "model": label,
                "structure": str(arx),
                "frequency_hz": plain_list(hz),
                "error_percent": plain_list(err),
            }
        )
    return rows


def rig_record(rig=None, noise_seed: int = 0) -> IOData:
    """Every sensor (:data:`RIG_OUTPUTS`) of the paper's simulated bang-bang
    experiment on `rig`.

    Parameters
    ----------
    rig : FlexibleManipulator, optional
        Default the default rig.
    noise_seed : int, default 0
        Seed of the sensor noise: the same seed gives the same run as the
        single-output record of that seed.

    Returns
    -------
    IOData
    """
    from spiralid.fms import FlexibleManipulator, paper_experiment

    rig = FlexibleManipulator() if rig is None else rig
    return paper_experiment().run(rig, rng=noise_seed).iodata(list(RIG_OUTPUTS))


def fit_every_sensor(
    record: IOData, fraction: float, seed: int, rig=None
) -> SharedModesFit:
    """One denominator for every sensor of `record`, validated on both parts.

    Parameters
    ----------
    record : IOData
        Every sensor of one run (:func:`rig_record`).
    fraction : float
        Estimation share of the record; the rest validates.
    seed : int
        The search's seed. It can end in another minimum with another
        seed, but the rig's three modes move by less than 0.02 % between
        them (docs/results/identification.md, "Several sensors").
    rig : FlexibleManipulator, optional
        The rig simulated, whose FEM modes the fit is set against; default
        the default rig.

    Returns
    -------
    SharedModesFit
    """
    from spiralid.fms import FlexibleManipulator

    est, val = record.split(fraction)
    start = time.perf_counter()
    model = identify(est, SHARED_ARX, integrator=RIG_INTEGRATORS, rng=seed)
    seconds = time.perf_counter() - start
    rig = FlexibleManipulator() if rig is None else rig
    return SharedModesFit(
        model=model,
        estimation=validate(model, est, label="every sensor (estimation)"),
        validation=validate(model, val, warmup=est, label="every sensor (validation)"),
        fem_hz=np.asarray(rig.modes(_FEM_MODES), dtype=float),
        seed=seed,
        seconds=seconds,
    )
