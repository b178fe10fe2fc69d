"""The one way a record is read: a shipped data set by name, or a file.

:func:`read_record` is what ``spiralid identify``, ``validate`` and
``reproduce`` read their DATA with and what a study file's ``csv`` records
go through, so a file that one of them reads, all of them read the same way.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from spiralid.sysid.data import (
    IOData,
    NoSampleTimeError,
    _csv_column,
    _csv_lookup,
    _csv_table,
)

__all__ = ["read_record"]

# Units of the columns `spiralid simulate` writes (their names carry them).
SIMULATE_UNITS = {
    "torque_Nm": "N m",
    "hub_angle_rad": "rad",
    "hub_velocity_rad_s": "rad/s",
    "end_acceleration_m_s2": "m/s^2",
}


def read_record(
    source: str | Path,
    input: str | int | None = None,
    output: str | int | None = None,
    ts: float | None = None,
    default_ts: float | None = None,
) -> IOData:
    """Read a record: a shipped data set's name, or a CSV, NPZ or MAT file.

    Parameters
    ----------
    source : str or Path
        A name of :data:`spiralid.datasets.NAMES`, or a file ending in
        ``.csv``, ``.npz`` or ``.mat``.
    input, output : str or int, optional
        Column (CSV: name or 0-based index) or variable (NPZ, MAT) names.
        Default ``u`` and ``y``, or for a CSV written by ``spiralid
        simulate`` its torque and end-point acceleration (with their units).
    ts : float, optional
        Sample time in seconds; default the file's own (a CSV's evenly spaced
        ``time_s`` column, an NPZ or MAT ``ts`` variable), else `default_ts`.
    default_ts : float, optional
        The sample time when neither `ts` nor the file gives one.

    Returns
    -------
    IOData
    """
    from spiralid import datasets

    file = Path(source)
    if not file.exists() and str(source) in datasets.NAMES:
        if (input, output) != (None, None):
            raise ValueError(
                f"`input` and `output` do not apply to the shipped data set "
                f"{str(source)!r}"
            )
        return datasets.load(str(source), ts)
    if not file.exists():
        raise ValueError(
            f"data file {str(source)!r} does not exist (shipped data sets: "
            f"{', '.join(datasets.NAMES)})"
        )
    if not file.is_file():
        raise ValueError(f"data file {str(source)!r} is not a file")
    suffix = file.suffix.lower()
    if suffix == ".csv":
        return _read_csv(file, input, output, ts, default_ts)
    if suffix in (".npz", ".mat"):
        input = "u" if input is None else input
        output = "y" if output is None else output
        if isinstance(input, int) or isinstance(output, int):
            raise ValueError(
                f"`input` and `output` must be variable names for {suffix} files"
            )
        loader = IOData.from_npz if suffix == ".npz" else IOData.from_mat
        try:
            return loader(file, input=input, output=output, ts=ts)
        except NoSampleTimeError:
            if default_ts is None:
                raise
            # The file carries no `ts`: fall back to the caller's default.
            return loader(file, input=input, output=output, ts=default_ts)
    raise ValueError(f"data file {str(source)!r} must end in .csv, .npz or .mat")


def _read_csv(file: Path, input, output, ts, default_ts) -> IOData:
    header, rows = _csv_table(file)
    header = header or []
    written_by_us = "torque_Nm" in header
    if input is None:
        input = "torque_Nm" if written_by_us else "u"
    if output is None:
        output = "end_acceleration_m_s2" if written_by_us else "y"
    time = _csv_lookup(header, "time_s", repr(str(file)))
    ts_file = None if time is None else _csv_sample_time(file, rows, time)
    if (
        ts is not None
        and ts_file is not None
        and not math.isclose(ts, ts_file, rel_tol=1e-5, abs_tol=1e-8)
    ):
        raise ValueError(
            f"`ts` {ts:g} contradicts the time_s column of {str(file)!r} (steps "
            f"of {ts_file:g} s); leave `ts` out or correct the file"
        )
    ts = next((t for t in (ts, ts_file, default_ts) if t is not None), None)
    if ts is None:
        raise ValueError(
            f"`ts` is required for {str(file)!r}: a CSV file carries no sample "
            "time (or give a 'time_s' column)"
        )
    data = IOData.from_csv(file, input=input, output=output, ts=ts)
    if written_by_us:
        data = replace(
            data,
            input_unit=SIMULATE_UNITS.get(data.input_name, data.input_unit),
            output_unit=SIMULATE_UNITS.get(data.output_name, data.output_unit),
        )
    return data


def _csv_sample_time(file: Path, rows: list, j: int) -> float:
    """The step of the evenly spaced ``time_s`` column `j` of `rows`.

    Every way the column can fail is said of the column, not of ``--ts``
    (which the user did not give) or of IOData's `ts` it would become."""
    where = f"the time_s column of {str(file)!r}"
    t = _csv_column(rows, j, "time_s", repr(str(file)))
    if t.size < 2:
        raise ValueError(f"{where} needs at least 2 samples to give a sample time")
    bad = ~np.isfinite(t)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(
            f"{where} must be finite; got {float(t[i])!r} on line {rows[i][0]}"
        )
    steps = np.diff(t)
    back = steps <= 0
    if back.any():
        i = int(np.argmax(back))
        raise ValueError(
            f"{where} must increase from sample to sample; it goes from "
            # + 0.0: a -0.0 says "0".
            f"{t[i] + 0.0:g} to {t[i + 1] + 0.0:g} s on line {rows[i + 1][0]}"
        )
    if not np.allclose(steps, steps[0], rtol=1e-6):
        raise ValueError(f"{where} is not evenly spaced")
    return float(steps.mean())
