"""The parsers of record files: delimited text (its header, units, time
column and encoding), ``.npz`` archives and MATLAB ``.mat`` files, each
refusing what it cannot read in one line. :class:`~spiralid.sysid.IOData`'s
``from_csv``, ``from_npz`` and ``from_mat`` build records from them."""

from __future__ import annotations

import codecs
import csv

import numpy as np


def _split_unit(header: str) -> tuple[str, str]:
    """``"torque [N m]"`` or ``"torque (N m)"`` -> ``("torque", "N m")``."""
    text = header.strip()
    for open_, close in ("[]", "()"):
        if text.endswith(close) and open_ in text:
            i = text.rindex(open_)
            return text[:i].strip(), text[i + 1 : -1].strip()
    return text, ""


def _output_keys(output, argname: str = "output") -> list:
    """The readers' `output` (or `input`): one column or variable, or a
    list of them for a record of several outputs (inputs)."""
    if isinstance(output, list | tuple):
        if not output:
            raise ValueError(f"`{argname}` must name at least one column; got []")
        if len(set(output)) != len(output):
            raise ValueError(f"`{argname}` must name each column once; got {output!r}")
        return list(output)
    return [output]


def _same_length(signals: dict, path, argname: str = "output") -> None:
    """Several output (input) variables, each a vector, all of one length:
    a one-line ValueError that names them otherwise."""
    for key, y in signals.items():
        if y.ndim != 1:
            raise ValueError(
                f"`{argname}` variable {key!r} of {str(path)!r} must be a vector "
                f"to be one of several; got shape {y.shape}"
            )
    lengths = {key: y.size for key, y in signals.items()}
    if len(set(lengths.values())) > 1:
        listed = ", ".join(f"{key!r} {n}" for key, n in lengths.items())
        raise ValueError(
            f"`{argname}` variables must have the same length; got {listed} "
            f"samples in {str(path)!r}"
        )


def _npz_arrays(path) -> dict:
    """The arrays of a ``.npz`` archive by name; anything that is not one,
    or holds Python objects, is refused in one line."""
    try:
        with open(path, "rb") as fh:
            magic = fh.read(4)
    except OSError as exc:
        raise ValueError(
            f"{str(path)!r} is not a readable .npz file ({exc.strerror})"
        ) from None
    if magic != b"PK\x03\x04":
        # np.load would take anything else for a pickle.
        raise ValueError(
            f"{str(path)!r} is not a .npz archive (a zip of .npy arrays, as "
            "numpy.savez writes)"
        )
    try:
        with np.load(path, allow_pickle=False) as z:
            mapping = dict(z.items())
    except ValueError as exc:
        if "allow_pickle" not in str(exc):
            raise
        raise ValueError(
            f"{str(path)!r} holds Python objects, which spiralid never "
            "unpickles (they can run code); save plain numeric arrays"
        ) from None
    except (OSError, EOFError) as exc:
        raise ValueError(f"{str(path)!r} is not a readable .npz file ({exc})") from None
    return mapping


def _mat_variables(path) -> dict:
    """The variables of a ``.mat`` file by name (MATLAB's ``__header__``
    and the like left out); anything scipy cannot read is refused in one
    line."""
    from scipy.io import loadmat
    from scipy.io.matlab import MatReadError

    where = repr(str(path))
    try:
        with open(path, "rb"):
            pass
    except OSError as exc:
        raise ValueError(
            f"{where} is not a readable .mat file ({exc.strerror or exc})"
        ) from None
    try:
        raw = loadmat(path)
    except NotImplementedError:
        # What scipy raises for MATLAB's HDF5-based format.
        raise ValueError(
            f"{where} is a MATLAB v7.3 file, which spiralid does not read; "
            "save it with save(..., '-v7')"
        ) from None
    except (MatReadError, ValueError) as exc:
        raise ValueError(
            f"{where} is not a readable .mat file ({' '.join(str(exc).split())})"
        ) from None
    except Exception:
        # SciPy's reader meets a truncated or corrupt file wherever its
        # parsing fails (an OSError "could not read bytes", zlib.error,
        # IndexError, KeyError...): none of them is a bug of ours.
        raise ValueError(
            f"{where} is not a readable .mat file (it is truncated or corrupt)"
        ) from None
    return {k: v for k, v in raw.items() if not k.startswith("__")}


def _csv_table(path, delimiter: str = ",") -> tuple[list[str] | None, list]:
    """The header of a delimited text file (None when its first line is all
    numbers) and its data rows, each as ``(line number, cells)``; blank
    lines are skipped."""
    where = repr(str(path))
    try:
        # utf-8-sig: a file saved by Excel starts with a byte-order mark.
        with open(path, newline="", encoding="utf-8-sig") as fh:
            reader = csv.reader(fh, delimiter=delimiter)
            rows = [(reader.line_num, r) for r in reader if r]
    except UnicodeDecodeError:
        raise ValueError(_not_utf8(path)) from None
    except csv.Error as exc:  # a NUL byte, a field beyond the csv module's limit
        raise ValueError(f"{where} is not a text CSV file ({exc})") from None
    if not rows:
        raise ValueError(f"{where} is empty")
    header = None
    if not all(_is_number(c) for c in rows[0][1]):
        header = [c.strip() for c in rows[0][1]]
        rows = rows[1:]
    return header, rows


def _csv_sample_time(where: str, rows: list, j: int) -> float:
    """The step of the evenly spaced ``time_s`` column `j` of `rows`.

    Every way the column can fail is said of the column, not of ``--ts``
    (which the user did not give) or of IOData's `ts` it would become."""
    what = f"the time_s column of {where}"
    t = _csv_column(rows, j, "time_s", where)
    if t.size < 2:
        raise ValueError(f"{what} needs at least 2 samples to give a sample time")
    bad = ~np.isfinite(t)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(
            f"{what} must be finite; got {float(t[i])!r} on line {rows[i][0]}"
        )
    steps = np.diff(t)
    back = steps <= 0
    if back.any():
        i = int(np.argmax(back))
        raise ValueError(
            f"{what} must increase from sample to sample; it goes from "
            # + 0.0: a -0.0 says "0".
            f"{t[i] + 0.0:g} to {t[i + 1] + 0.0:g} s on line {rows[i + 1][0]}"
        )
    if not np.allclose(steps, steps[0], rtol=1e-6):
        raise ValueError(f"{what} is not evenly spaced")
    return float(steps.mean())


def _csv_lookup(header: list[str], key, where: str, argname: str = "") -> int | None:
    """The index of the column `key` names: its whole header, else the name
    before its unit; None when no column has that name.

    A name that two columns share is refused rather than resolved to the
    first: which of them the user meant is theirs to say."""
    for names in (header, [_split_unit(h)[0] for h in header]):
        found = [j for j, name in enumerate(names) if name == key]
        if len(found) > 1:
            how = f", or give `{argname}` as a column index" if argname else ""
            which = ", ".join(map(str, found[:-1])) + f" and {found[-1]}"
            raise ValueError(
                f"{where} has {len(found)} columns named {key!r} (columns "
                f"{which}, counting from 0): rename them so that each column "
                f"has its own name{how}"
            )
        if found:
            return found[0]
    return None


def _csv_column(rows: list, j: int, name: str, where: str) -> np.ndarray:
    """Column `j` of `rows` (from :func:`_csv_table`) as floats; a cell that
    is not a number is refused with its line."""
    out = np.empty(len(rows))
    for r, (line, row) in enumerate(rows):
        cell = row[j].strip() if j < len(row) else ""
        try:
            out[r] = float(cell)
        except ValueError:
            raise ValueError(
                f"column {name!r} of {where} must be numeric; got {cell!r} "
                f"on line {line}"
            ) from None
    return out


def _not_utf8(path) -> str:
    """Why a file that UTF-8 cannot decode is refused, and how to fix it:
    binary data, UTF-16, or text in a legacy 8-bit encoding."""
    where = repr(str(path))
    with open(path, "rb") as fh:
        if _utf16_text(fh.read(1 << 16)):
            return (
                f"{where} is UTF-16 text, not UTF-8: save it as UTF-8 (in Excel: "
                "'CSV UTF-8'), or convert it with iconv -f utf-16 -t utf-8"
            )
        fh.seek(0)
        decoder = codecs.getincrementaldecoder("utf-8")()
        line = 1
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            if b"\x00" in chunk:
                break
            try:
                decoder.decode(chunk)
            except UnicodeDecodeError as exc:
                # Bytes held over from the previous chunk are part of one
                # character, never a line break.
                line += exc.object.count(b"\n", 0, exc.start)
                return (
                    f"{where} is not UTF-8 text (byte 0x{exc.object[exc.start]:02x} "
                    f"on line {line}, perhaps Latin-1 or Windows-1252): save it "
                    "as UTF-8 (in Excel: 'CSV UTF-8'), or convert it with "
                    "iconv -f latin1 -t utf-8"
                )
            line += chunk.count(b"\n")
    return f"{where} is not a text CSV file (it holds binary data)"


def _utf16_text(head: bytes) -> bool:
    """Whether `head`, a file's first bytes, is delimited text in UTF-16 (as
    Excel's "Unicode text" writes it): a byte-order mark, then characters
    that decode and hold a line break or a delimiter."""
    if head[:2] not in (b"\xff\xfe", b"\xfe\xff"):
        return False
    text = head[: len(head) // 2 * 2].decode("utf-16", errors="replace")
    return "\ufffd" not in text[:-1] and any(c in text for c in ",;\t\n")


class NoSampleTimeError(ValueError):
    """A record file that carries no sample time, and none was given."""


def _file_sample_time(value, path) -> float:
    """A file's ``ts`` variable as a positive float.

    Checked here rather than by IOData, whose message would blame the `ts`
    argument for what the file holds."""
    where = f"the variable 'ts' of {str(path)!r}"
    a = np.asarray(value)
    if a.dtype.kind not in "fiub":
        what = "a complex value" if a.dtype.kind == "c" else "non-numeric data"
        raise ValueError(
            f"{where} must be a real number (the sample time in seconds); got {what}"
        )
    if a.size != 1:
        raise ValueError(f"{where} must be a scalar; got shape {a.shape}")
    ts = float(a.ravel()[0])
    if not (np.isfinite(ts) and ts > 0):
        raise ValueError(
            f"{where} must be a positive number (the sample time in seconds); "
            f"got {ts!r}"
        )
    return ts


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _several(values: list, stack: bool = False):
    """One value for one channel, a tuple (or the columns stacked) for
    several."""
    if len(values) == 1:
        return values[0]
    return np.column_stack(values) if stack else tuple(values)


def _table_fields(header, rows, input, output, ts, default_ts, path) -> dict:
    """The keyword arguments of an :class:`~spiralid.sysid.IOData` read from
    a table :func:`_csv_table` has read (``IOData.from_csv``)."""
    import math

    where = repr(str(path))
    time = None if header is None else _csv_lookup(header, "time_s", where)
    ts_file = None if time is None else _csv_sample_time(where, rows, time)
    if (
        ts is not None
        and ts_file is not None
        and not math.isclose(ts, ts_file, rel_tol=1e-5, abs_tol=1e-8)
    ):
        raise ValueError(
            f"`ts` {ts:g} contradicts the time_s column of {where} (steps "
            f"of {ts_file:g} s); leave `ts` out or correct the file"
        )
    ts = next((t for t in (ts, ts_file, default_ts) if t is not None), None)
    if ts is None:
        raise NoSampleTimeError(
            f"`ts` is required for {where}: a CSV file carries no sample "
            "time (or give a 'time_s' column)"
        )
    ncol = len(header) if header is not None else len(rows[0][1])

    def column(key, argname):
        if isinstance(key, (int, np.integer)) and not isinstance(key, bool):
            if not 0 <= key < ncol:
                raise ValueError(
                    f"`{argname}` column index must be in [0, {ncol - 1}]; got {key!r}"
                )
            j = int(key)
        elif header is None:
            raise ValueError(
                f"`{argname}` must be a column index: {where} has no header "
                f"line; got {key!r}"
            )
        else:
            j = _csv_lookup(header, key, where, argname)
            if j is None:
                raise ValueError(
                    f"`{argname}` must be one of the columns {header}; got {key!r}"
                )
        return j, *(_split_unit(header[j]) if header else (f"column {j}", ""))

    fields = {"ts": ts}
    for arg, kind, short in (("input", input, "u"), ("output", output, "y")):
        found = [column(key, arg) for key in _output_keys(kind, arg)]
        fields[short] = _several(
            [_csv_column(rows, j, name, where) for j, name, _ in found], stack=True
        )
        fields[f"{arg}_name"] = _several([name for _, name, _ in found])
        fields[f"{arg}_unit"] = _several([unit for _, _, unit in found])
    return fields


def _mapping_fields(mapping, input, output, ts, path, default_ts) -> dict:
    """The keyword arguments of an :class:`~spiralid.sysid.IOData` read
    from a file's arrays by name (``.npz``, ``.mat``)."""
    names = sorted(mapping)
    keys = {"input": _output_keys(input, "input"), "output": _output_keys(output)}
    for arg, some in keys.items():
        for key in some:
            if key not in mapping:
                raise ValueError(
                    f"`{arg}` must be one of the variables {names}; got {key!r}"
                )
    if ts is None and "ts" not in mapping and default_ts is not None:
        ts = default_ts
    if ts is None:
        if "ts" not in mapping:
            raise NoSampleTimeError(
                f"`ts` must be given: {str(path)!r} has no variable 'ts' "
                f"(variables: {names})"
            )
        ts = _file_sample_time(mapping["ts"], path)

    def arr(key, arg):
        a = np.asarray(mapping[key])
        if a.dtype.kind == "c":
            raise ValueError(
                f"`{arg}` variable {key!r} of {str(path)!r} must be real-valued; "
                "got complex values (save its real part or magnitude instead)"
            )
        if a.dtype.kind not in "fiub":
            raise ValueError(
                f"`{arg}` variable {key!r} must be numeric; got dtype {a.dtype} "
                f"in {str(path)!r}"
            )
        a = a.astype(float)
        # MATLAB stores vectors as (1, N) or (N, 1).
        return a.ravel() if a.ndim == 2 and 1 in a.shape else a

    fields = {"ts": ts}
    for (arg, some), short in zip(keys.items(), "uy", strict=True):
        signals = [arr(key, arg) for key in some]
        if len(some) > 1:
            _same_length(dict(zip(some, signals, strict=True)), path, arg)
        fields[short] = _several(signals, stack=True)
        fields[f"{arg}_name"] = _several([str(k) for k in some])
    return fields
