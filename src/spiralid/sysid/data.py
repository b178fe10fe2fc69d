"""Input-output records: validated signals, sample time, loading, split, detrend."""

from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from spiralid._checks import named_index, positive

from .readers import (
    NoSampleTimeError as NoSampleTimeError,
)
from .readers import (
    _csv_table,
    _mapping_fields,
    _mat_variables,
    _npz_arrays,
    _table_fields,
)
from .signals import _check_magnitude, check_outputs, per_channel

__all__ = ["IOData"]


def single_output_record(data, what: str):
    """`data` checked as an :class:`IOData` of one input and one output,
    for `what` (a function that models one output from one input): a
    one-line TypeError (not an IOData) or ValueError (several outputs or
    inputs) otherwise."""
    if not isinstance(data, IOData):
        raise TypeError(f"`data` must be an IOData; got {type(data).__name__}")
    data.require_single_output(what)
    data.require_single_input(what)
    return data


def _frozen(checked: np.ndarray) -> np.ndarray:
    # A private read-only copy: IOData is immutable, and freezing the
    # caller's own array instead would make it read-only behind their back.
    arr = np.array(checked, dtype=float, order="C", copy=True)
    arr.flags.writeable = False
    return arr


def _label(name: str, unit: str) -> str:
    return f"{name} ({unit})" if unit else name


def _check_ts(ts) -> float:
    return positive(ts, "ts")


@dataclass(frozen=True, eq=False)
class IOData:
    """A record of one or several inputs and one or several outputs,
    sampled every `ts` seconds.

    Parameters
    ----------
    u : array_like, shape (N,), (N, 1) or (N, m)
        Input samples; finite: one input (stored as shape (N,), the simple
        case every single-input function takes), or ``m >= 2`` inputs, one
        per column (a structure driven by several shakers).
    y : array_like, shape (N,), (N, 1) or (N, p)
        Output samples, as long as `u` and finite: one output (stored as
        shape (N,), the simple case every single-output function takes), or
        ``p >= 2`` outputs that share the input, one per column (a
        flexible structure's sensors).
    ts : float
        Sample time in seconds (> 0).
    input_name, output_name : str
        Labels used in tables and plots; with several outputs
        `output_name` is one name per output (default ``y1, y2, ...``),
        with several inputs `input_name` one per input (``u1, u2, ...``).
    input_unit, output_unit : str
        Units of `u` and `y` (e.g. ``"N m"``, ``"m/s^2"``), shown in every
        figure and table; empty when unknown. With several outputs
        (inputs) `output_unit` (`input_unit`) is one unit for all or one
        per output (input).
    u_offset, y_offset : float
        Offsets already removed from the signals (set by :meth:`detrend`);
        add them back to recover the raw signals. With several outputs
        (inputs) `y_offset` (`u_offset`) is one per output (input).

    Notes
    -----
    With several outputs, ``output_name``, ``output_unit`` and ``y_offset``
    are tuples with one entry per output; :attr:`output_names`,
    :attr:`output_units` and :attr:`y_offsets` are tuples in every case,
    :meth:`output` picks one output as a single-output record, and a
    function that models one output refuses several in one line
    (:meth:`require_single_output`). Several inputs mirror it:
    ``input_name``, ``input_unit`` and ``u_offset`` are then tuples,
    :attr:`input_names`, :attr:`input_units`, :attr:`u_offsets` and
    :attr:`inputs` (N, m) hold in every case, :meth:`input` picks one, and
    a function that takes one input refuses several
    (:meth:`require_single_input`).

    Examples
    --------
    >>> d = IOData([0.0, 1.0, 0.0, -1.0], [0.0, 0.0, 0.5, 0.2], ts=0.1)
    >>> d.n, d.t[-1].round(3)
    (4, np.float64(0.3))
    >>> est, val = d.split(0.5)
    >>> est.n, val.n
    (2, 2)
    """

    u: np.ndarray
    y: np.ndarray
    ts: float
    input_name: str | tuple[str, ...] = "u"
    output_name: str | tuple[str, ...] = "y"
    u_offset: float | tuple[float, ...] = field(default=0.0)
    y_offset: float | tuple[float, ...] = field(default=0.0)
    input_unit: str | tuple[str, ...] = ""
    output_unit: str | tuple[str, ...] = ""

    def __post_init__(self) -> None:
        u = _frozen(check_outputs(self.u, "u"))
        y = _frozen(check_outputs(self.y, "y"))
        if u.shape[0] != y.shape[0]:
            raise ValueError(
                f"`u` and `y` must have the same length; got {u.shape[0]} and "
                f"{y.shape[0]}"
            )
        _check_magnitude(u, "u")
        _check_magnitude(y, "y")
        object.__setattr__(self, "u", u)
        object.__setattr__(self, "y", y)
        object.__setattr__(self, "ts", _check_ts(self.ts))
        self._channels(u, ("input_name", "u_offset", "input_unit"), "input")
        self._channels(y, ("output_name", "y_offset", "output_unit"), "output")

    def _channels(self, x: np.ndarray, fields: tuple, what: str) -> None:
        """The name, offset and unit fields of the inputs or the outputs
        `x`: scalars for one, tuples of one per column for several."""
        name, offset, unit = fields
        if x.ndim == 1:
            object.__setattr__(self, name, str(getattr(self, name)))
            object.__setattr__(self, offset, float(getattr(self, offset)))
            object.__setattr__(self, unit, str(getattr(self, unit)))
            return
        p = x.shape[1]
        names = getattr(self, name)
        if isinstance(names, str):
            names = tuple(f"{names}{k + 1}" for k in range(p))
        names = per_channel(names, p, name, str, what)
        if len(set(names)) != p:
            raise ValueError(f"`{name}` must name each {what} once; got {names}")
        object.__setattr__(self, name, names)
        for field_, kind in ((offset, float), (unit, str)):
            value = per_channel(getattr(self, field_), p, field_, kind, what)
            object.__setattr__(self, field_, value)

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.u.shape[0])

    def __len__(self) -> int:
        return self.n

    @property
    def n_outputs(self) -> int:
        """Number of outputs ``p`` (1 for a single-output record)."""
        return 1 if self.y.ndim == 1 else int(self.y.shape[1])

    @property
    def output_names(self) -> tuple[str, ...]:
        """One name per output."""
        return (self.output_name,) if self.y.ndim == 1 else self.output_name

    @property
    def output_units(self) -> tuple[str, ...]:
        """One unit per output."""
        return (self.output_unit,) if self.y.ndim == 1 else self.output_unit

    @property
    def y_offsets(self) -> tuple[float, ...]:
        """One removed offset per output."""
        return (self.y_offset,) if self.y.ndim == 1 else self.y_offset

    @property
    def n_inputs(self) -> int:
        """Number of inputs ``m`` (1 for a single-input record)."""
        return 1 if self.u.ndim == 1 else int(self.u.shape[1])

    @property
    def input_names(self) -> tuple[str, ...]:
        """One name per input."""
        return (self.input_name,) if self.u.ndim == 1 else self.input_name

    @property
    def input_units(self) -> tuple[str, ...]:
        """One unit per input."""
        return (self.input_unit,) if self.u.ndim == 1 else self.input_unit

    @property
    def u_offsets(self) -> tuple[float, ...]:
        """One removed offset per input."""
        return (self.u_offset,) if self.u.ndim == 1 else self.u_offset

    @property
    def inputs(self) -> np.ndarray:
        """The inputs as an (N, m) array, whatever ``m`` (a read-only view)."""
        return self.u.reshape(self.n, self.n_inputs)

    def input(self, which: int | str) -> IOData:
        """One input, by 0-based index or name, as a single-input record of
        the same outputs (the record itself when it has one input and
        `which` names it): the part of a several-input record a function
        of one input takes, the others' response then left in ``y``."""
        k = named_index(which, "which", self.input_names)
        if self.u.ndim == 1:
            return self
        return self._replace(
            self.u[:, k],
            self.y,
            input_name=self.input_names[k],
            u_offset=self.u_offsets[k],
            input_unit=self.input_units[k],
        )

    def require_single_input(self, what: str) -> None:
        """A one-line ValueError when the record has several inputs: `what`
        (e.g. ``"identify with an ARX structure"``) takes one."""
        if self.u.ndim != 1:
            raise ValueError(
                f"`data` has {self.n_inputs} inputs {self.input_names}; {what} "
                "takes one: pass data.input(name), or fit a shared denominator"
            )

    @property
    def outputs(self) -> np.ndarray:
        """The outputs as an (N, p) array, whatever ``p`` (a read-only view)."""
        return self.y.reshape(self.n, self.n_outputs)

    def output(self, which: int | str) -> IOData:
        """One output, by 0-based index or name, as a single-output record
        with its own name, unit and offset (the record itself when it has
        one output and `which` names it)."""
        names = self.output_names
        k = named_index(which, "which", names)
        if self.y.ndim == 1:
            return self
        return self._replace(
            self.u,
            self.y[:, k],
            output_name=names[k],
            y_offset=self.y_offsets[k],
            output_unit=self.output_units[k],
        )

    def select_outputs(self, which, *, rename=None) -> IOData:
        """The outputs `which` (names or 0-based indices) in that order, each
        with its own unit and offset, optionally renamed to `rename` (one
        name per output).

        Examples
        --------
        >>> d = IOData([0.0, 1.0], [[1.0, 2.0], [3.0, 4.0]], ts=1.0,
        ...            output_name=("vel", "acc"))
        >>> d.select_outputs(["acc", "vel"]).outputs.tolist()
        [[2.0, 1.0], [4.0, 3.0]]
        >>> d.select_outputs([1], rename=["tip"]).output_names
        ('tip',)
        """
        ones = [self.output(w) for w in which]
        if not ones:
            raise ValueError("`which` must name at least one output")
        names = [o.output_name for o in ones] if rename is None else list(rename)
        if len(names) != len(ones):
            raise ValueError(
                f"`rename` must have one name per output ({len(ones)}); got "
                f"{len(names)}"
            )
        several = len(ones) > 1
        return self._replace(
            self.u,
            np.column_stack([o.y for o in ones]) if several else ones[0].y,
            output_name=tuple(names) if several else names[0],
            y_offset=tuple(o.y_offset for o in ones) if several else ones[0].y_offset,
            output_unit=tuple(o.output_unit for o in ones)
            if several
            else ones[0].output_unit,
        )

    def require_single_output(self, what: str) -> None:
        """A one-line ValueError when the record has several outputs:
        `what` (e.g. ``"identify with an ARX structure"``) models one."""
        if self.y.ndim != 1:
            raise ValueError(
                f"`data` has {self.n_outputs} outputs {self.output_names}; {what} "
                "takes one: pass data.output(name)"
            )

    @property
    def t(self) -> np.ndarray:
        """Sample instants ``0, ts, 2 ts, ...`` in seconds."""
        return np.arange(self.n) * self.ts

    @property
    def input_label(self) -> str:
        """``"name (unit)"``, or the name alone when the unit is unknown
        (joined by commas for several inputs)."""
        return ", ".join(
            _label(n, unit)
            for n, unit in zip(self.input_names, self.input_units, strict=True)
        )

    @property
    def output_label(self) -> str:
        """``"name (unit)"``, or the name alone when the unit is unknown
        (joined by commas for several outputs)."""
        return ", ".join(
            _label(n, unit)
            for n, unit in zip(self.output_names, self.output_units, strict=True)
        )

    def __repr__(self) -> str:
        return (
            f"IOData(n={self.n}, ts={self.ts!r}, input_name={self.input_name!r}, "
            f"output_name={self.output_name!r})"
        )

    def provenance(self) -> dict:
        """The signals' names, units and removed offsets, which a model
        estimated on this record carries (:class:`IdentifiedModel`,
        :class:`NARXModel`) so that it is validated and drawn in them."""
        return dict(
            input_name=self.input_name,
            output_name=self.output_name,
            input_unit=self.input_unit,
            output_unit=self.output_unit,
            u_offset=self.u_offset,
            y_offset=self.y_offset,
        )

    def _replace(self, u, y, **kw) -> IOData:
        return IOData(u, y, **{"ts": self.ts, **self.provenance(), **kw})

    def __getitem__(self, index: slice) -> IOData:
        """A contiguous part, ``data[a:b]`` (slices with step 1 only)."""
        if not isinstance(index, slice) or index.step not in (None, 1):
            raise ValueError(
                f"`index` must be a slice with step 1, e.g. data[10:50]; got {index!r}"
            )
        return self._replace(self.u[index], self.y[index])

    def split(self, fraction: float = 2 / 3) -> tuple[IOData, IOData]:
        """Split into contiguous (estimation, validation) parts.

        The paper (Section "Model validation") estimates on the first two
        thirds and validates on the rest. The estimation part has
        ``round(fraction * n)`` samples.

        Parameters
        ----------
        fraction : float
            Share of samples in the estimation part, in (0, 1).
        """
        try:
            frac = float(fraction)
        except (TypeError, ValueError):
            raise ValueError(
                f"`fraction` must be a number in (0, 1); got {fraction!r}"
            ) from None
        if not (0.0 < frac < 1.0):
            raise ValueError(f"`fraction` must be in (0, 1); got {fraction!r}")
        k = round(frac * self.n)
        if k < 1 or k > self.n - 1:
            raise ValueError(
                f"`fraction` leaves an empty part of a record of {self.n} samples; "
                f"got {fraction!r}"
            )
        return self[:k], self[k:]

    def detrend(self, like: IOData | None = None) -> IOData:
        """Remove the means of input and output, remembering them as offsets.

        Parameters
        ----------
        like : IOData, optional
            Remove this record's means instead of our own: detrend a whole
            record by its estimation part, ``data.detrend(like=est)``, so the
            validation part is shifted by the offsets the model was
            estimated with, as new data would be.

        Returns
        -------
        IOData
            Shifted signals; ``u_offset`` / ``y_offset`` accumulate the
            removed means so ``data.y + data.y_offset`` is the raw output.

        Examples
        --------
        >>> d = IOData([1.0, 3.0, 5.0, 7.0], [10.0, 10.0, 12.0, 12.0], ts=1.0)
        >>> d.detrend().y.tolist(), d.detrend().y_offset
        ([-1.0, -1.0, 1.0, 1.0], 11.0)
        >>> est, _ = d.split(0.5)
        >>> d.detrend(like=est).u.tolist()
        [-1.0, 1.0, 3.0, 5.0]
        """
        ref = self if like is None else like
        if not isinstance(ref, IOData):
            raise TypeError(f"`like` must be an IOData; got {type(like).__name__}")
        if ref.n_outputs != self.n_outputs:
            raise ValueError(
                f"`like` must have the record's {self.n_outputs} output(s); got "
                f"{ref.n_outputs}"
            )
        if ref.n_inputs != self.n_inputs:
            raise ValueError(
                f"`like` must have the record's {self.n_inputs} input(s); got "
                f"{ref.n_inputs}"
            )
        if self.u.ndim == 1:
            mu = float(ref.u.mean())
            u_offset = self.u_offset + mu
        else:
            mu = ref.u.mean(axis=0)
            u_offset = tuple(
                float(a + b) for a, b in zip(self.u_offset, mu, strict=True)
            )
        if self.y.ndim == 1:
            my = float(ref.y.mean())
            offset = self.y_offset + my
        else:
            my = ref.y.mean(axis=0)
            offset = tuple(float(a + b) for a, b in zip(self.y_offset, my, strict=True))
        return self._replace(
            self.u - mu, self.y - my, u_offset=u_offset, y_offset=offset
        )

    # -- loading ---------------------------------------------------------------

    @classmethod
    def from_csv(
        cls,
        path: str | os.PathLike,
        input: str | int | list = "u",
        output: str | int | list = "y",
        ts: float | None = None,
        delimiter: str = ",",
        *,
        default_ts: float | None = None,
    ) -> IOData:
        """Read the input and output columns of a delimited text file (opened once).

        Parameters
        ----------
        path : path-like
            The file. A first line that is not all numbers is read as a header.
        input, output : str, int or list
            Column names (needs a header) or 0-based column indices. A header
            may carry units as ``name [unit]`` or ``name (unit)``; the column
            is then named by either the whole header or ``name``, and the
            unit goes to ``input_unit`` / ``output_unit``. Either may be a
            list of columns: a record of several outputs, ``y`` of shape
            (N, p), or of several inputs, ``u`` of shape (N, m).
        ts : float, optional
            Sample time in seconds; default the step of an evenly spaced
            ``time_s`` column, else `default_ts`.
        delimiter : str
            Field separator.
        default_ts : float, optional
            The sample time when neither `ts` nor a ``time_s`` column gives
            one (:class:`NoSampleTimeError` when none does).
        """
        header, rows = _csv_table(path, delimiter)
        return cls._from_table(header, rows, input, output, ts, default_ts, path)

    @classmethod
    def _from_table(cls, header, rows, input, output, ts, default_ts, path) -> IOData:
        """:meth:`from_csv` on a table :func:`_csv_table` has read."""
        return cls(**_table_fields(header, rows, input, output, ts, default_ts, path))

    @classmethod
    def from_npz(
        cls,
        path: str | os.PathLike,
        input: str | list = "u",
        output: str | list = "y",
        ts: float | None = None,
        *,
        default_ts: float | None = None,
    ) -> IOData:
        """Read two arrays of a NumPy ``.npz`` archive (never unpickles objects).

        Parameters
        ----------
        path : path-like
            The archive, as :func:`numpy.savez` writes it.
        input, output : str or list
            The names of the input and output arrays; a (1, N) or (N, 1)
            array is read as a vector. Either may be a list of names: a
            record of several outputs, ``y`` of shape (N, p), or inputs,
            ``u`` of shape (N, m).
        ts : float, optional
            Sample time in seconds; default the scalar array named ``ts``,
            else `default_ts`.
        default_ts : float, optional
            The sample time when neither `ts` nor the file gives one
            (:class:`NoSampleTimeError` when none does).
        """
        return cls._from_mapping(_npz_arrays(path), input, output, ts, path, default_ts)

    @classmethod
    def from_mat(
        cls,
        path: str | os.PathLike,
        input: str | list = "u",
        output: str | list = "y",
        ts: float | None = None,
        *,
        default_ts: float | None = None,
    ) -> IOData:
        """Read two variables of a MATLAB ``.mat`` file (``scipy.io.loadmat``;
        MATLAB's v7.3 files are refused), with the arguments of
        :meth:`from_npz`, variables in place of arrays."""
        return cls._from_mapping(
            _mat_variables(path), input, output, ts, path, default_ts
        )

    @classmethod
    def _from_mapping(cls, mapping, input, output, ts, path, default_ts) -> IOData:
        """The one reader of the formats that hold named arrays (.npz, .mat):
        `mapping` is the file's arrays by name."""
        return cls(**_mapping_fields(mapping, input, output, ts, path, default_ts))
