"""The one way a record is read: a shipped data set by name, or a file.

:func:`read_record` is what ``spiralid identify``, ``validate`` and
``reproduce`` read their DATA with and what a study file's ``csv`` records
go through, so a file that one of them reads, all of them read the same way.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from spiralid.datasets.shipped import NAMES, load
from spiralid.sysid.data import IOData
from spiralid.sysid.readers import _csv_table

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
    input: str | int | list | None = None,
    output: str | int | list | None = None,
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
        Column (CSV: name or 0-based index) or variable (NPZ, MAT) names;
        either may be a list of them (a record of several outputs or
        inputs).
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
    file = Path(source)
    if not file.exists() and str(source) in NAMES:
        if (input, output) != (None, None):
            raise ValueError(
                f"`input` and `output` do not apply to the shipped data set "
                f"{str(source)!r}"
            )
        return load(str(source), ts)
    if not file.exists():
        raise ValueError(
            f"data file {str(source)!r} does not exist (shipped data sets: "
            f"{', '.join(NAMES)})"
        )
    if not file.is_file():
        raise ValueError(f"data file {str(source)!r} is not a file")
    suffix = file.suffix.lower()
    if suffix == ".csv":
        return _read_csv(file, input, output, ts, default_ts)
    if suffix in (".npz", ".mat"):
        input = "u" if input is None else input
        output = "y" if output is None else output
        given = [
            *(input if isinstance(input, list | tuple) else [input]),
            *(output if isinstance(output, list | tuple) else [output]),
        ]
        if any(isinstance(key, int) for key in given):
            raise ValueError(
                f"`input` and `output` must be variable names for {suffix} files"
            )
        loader = IOData.from_npz if suffix == ".npz" else IOData.from_mat
        return loader(file, input=input, output=output, ts=ts, default_ts=default_ts)
    raise ValueError(f"data file {str(source)!r} must end in .csv, .npz or .mat")


def _read_csv(file: Path, input, output, ts, default_ts) -> IOData:
    """IOData's CSV reader on a table read once, with the column names and
    units of a file that ``spiralid simulate`` wrote."""
    header, rows = _csv_table(file)
    written_by_us = "torque_Nm" in (header or [])
    if input is None:
        input = "torque_Nm" if written_by_us else "u"
    if output is None:
        output = "end_acceleration_m_s2" if written_by_us else "y"
    data = IOData._from_table(header, rows, input, output, ts, default_ts, file)
    if written_by_us:
        data = replace(
            data,
            input_unit=tuple(
                SIMULATE_UNITS.get(name, unit)
                for name, unit in zip(data.input_names, data.input_units, strict=True)
            )
            if data.n_inputs > 1
            else SIMULATE_UNITS.get(data.input_name, data.input_unit),
            output_unit=tuple(
                SIMULATE_UNITS.get(name, unit)
                for name, unit in zip(data.output_names, data.output_units, strict=True)
            )
            if data.n_outputs > 1
            else SIMULATE_UNITS.get(data.output_name, data.output_unit),
        )
    return data
