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


def _output_keys(output) -> list:
    """The readers' `output`: one column or variable, or a list of them for
    a record of several outputs."""
    if isinstance(output, list | tuple):
        if not output:
            raise ValueError("`output` must name at least one column; got []")
        if len(set(output)) != len(output):
            raise ValueError(f"`output` must name each column once; got {output!r}")
        return list(output)
    return [output]


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
