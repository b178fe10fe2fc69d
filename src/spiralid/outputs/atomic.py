"""Atomic output: a folder (or file) appears complete or not at all.

Everything is written into a staging folder beside the target and moved
into place only when complete, so an interrupted or failed run leaves
nothing behind, and a later run is never refused because of a half-written
folder. A lock file beside the target refuses a second writer while the
first one runs; writability is tested when the folder is opened, before any
computation.

The rules a user relies on (docs/guide/cli.md, "Output folders"):

- a target folder must be new or empty unless ``force``; with ``force`` the
  files written replace those of the same name and nothing else in the
  folder is touched;
- a target file is never overwritten without ``force``, even when another
  process creates it while we compute (the final step is a no-clobber link).
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import shutil
import signal
import tempfile
from pathlib import Path

__all__ = ["OutputError", "OutputFile", "OutputFolder"]

_STAGING = ".spiralid-staging-"
_LOCK = ".spiralid-lock-"


class OutputError(ValueError):
    """The output cannot be written: exists, locked, not writable."""


def _why(exc: OSError) -> str:
    if exc.errno in (errno.EACCES, errno.EPERM):
        return "permission denied"
    if exc.errno == errno.EROFS:
        return "read-only file system"
    if exc.errno == errno.ENOSPC:
        return "no space left on device"
    return exc.strerror or str(exc)


def _umask() -> int:
    """The process's umask, read without changing it where Linux allows."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _publish_mode(path: Path, directory: bool) -> None:
    """Give a staged file or folder the mode a plain ``open``/``mkdir`` would
    have given it under the user's umask (staging uses private 0600/0700
    temporaries, which would otherwise make the output unreadable to
    others)."""
    base = 0o777 if directory else 0o666
    os.chmod(path, base & ~_umask())


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # alive, another user's
        return True
    return True


def _staging_prefix() -> str:
    # The process id in the name tells a later run whether its writer is
    # still alive (see _remove_stale).
    return f"{_STAGING}{os.getpid()}-"


def _remove_stale(folder: Path) -> list[str]:
    """Remove what killed runs left in `folder`: lock files nobody holds and
    staging files or folders whose process is gone. Returns their names."""
    removed = []
    for lock in folder.glob(f"{_LOCK}*"):
        try:
            fd = os.open(lock, os.O_RDWR)
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)  # held: a live run
            continue
        with contextlib.suppress(OSError):
            os.unlink(lock)
            removed.append(lock.name)
        os.close(fd)
    for staged in folder.glob(f"{_STAGING}*"):
        pid = staged.name[len(_STAGING) :].split("-", 1)[0]
        if pid.isdigit() and _pid_alive(int(pid)):
            continue
        if staged.is_dir():
            shutil.rmtree(staged, ignore_errors=True)
        else:
            with contextlib.suppress(OSError):
                staged.unlink()
        removed.append(staged.name)
    return removed


def _note_stale(folder: Path) -> None:
    removed = _remove_stale(folder)
    if removed:
        import warnings

        warnings.warn(
            f"removed {len(removed)} file(s) left in {str(folder)!r} by a spiralid "
            f"run that was killed ({', '.join(sorted(removed)[:3])})",
            stacklevel=3,
        )


@contextlib.contextmanager
def _signals_deferred():
    """Hold SIGINT/SIGTERM while files are created or moved into place, and
    deliver them when the block ends.

    A Python-level handler that only records, not a blocked signal mask: the
    mask is per thread, and a signal the kernel hands to another thread (a
    BLAS worker) would still reach Python's handler at once.
    """
    held: list[int] = []

    def hold(signum, frame):
        held.append(signum)

    previous = {}
    try:
        for signum in (signal.SIGINT, signal.SIGTERM):
            previous[signum] = signal.signal(signum, hold)
    except ValueError:  # not the main thread: nothing to hold
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        yield
        return
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        for signum in dict.fromkeys(held):
            signal.raise_signal(signum)


def _make_parents(folder: Path) -> list[Path]:
    """Create `folder` and its missing parents; return those created, deepest
    first, so a failed run can remove exactly what it made."""
    missing = []
    p = folder
    while not p.exists():
        missing.append(p)
        p = p.parent
    for d in reversed(missing):
        try:
            d.mkdir()
        except FileExistsError:
            pass
        except OSError as exc:
            _remove_empty(missing[missing.index(d) + 1 :])
            raise OutputError(
                f"cannot create the folder {str(d)!r}: {_why(exc)}"
            ) from None
    return missing


def _remove_empty(folders: list[Path]) -> None:
    for d in folders:
        with contextlib.suppress(OSError):
            d.rmdir()


def _replace(source: Path, target: Path) -> None:
    """Move `source` onto `target`; a folder onto an existing folder is
    merged file by file (the files written replace those of the same name,
    nothing else in it is touched), as the target folder itself is."""
    if source.is_dir() and target.is_dir() and not target.is_symlink():
        for child in sorted(source.iterdir()):
            _replace(child, target / child.name)
        source.rmdir()
        return
    os.replace(source, target)


def _surplus(
    staged: Path, target: Path, pattern: str | None
) -> tuple[list[Path], set[str]]:
    """The folders matching `pattern` in `target` that `staged` does not
    hold, and the names of the files the staged ones hold (see
    :meth:`OutputFolder.commit`)."""
    if pattern is None:
        return [], set()
    fresh = [p for p in staged.glob(pattern) if p.is_dir()]
    ours = {f.name for p in fresh for f in p.iterdir() if f.is_file()}
    kept = {p.name for p in fresh}
    old = [
        p
        for p in target.glob(pattern)
        if p.name not in kept and p.is_dir() and not p.is_symlink()
    ]
    return old, ours


def _clear(folders: list[Path], names: set[str]) -> None:
    """Remove the files `names` from `folders`, and each folder once empty."""
    for folder in folders:
        for name in names:
            with contextlib.suppress(FileNotFoundError):
                (folder / name).unlink()
        with contextlib.suppress(OSError):  # holds something of the user's
            folder.rmdir()


class _Lock:
    """An exclusive ``flock`` on a file beside the target, removed on release.

    ``flock`` dies with its process, so a killed run never leaves a stale
    lock held; the file itself is removed on release, and a locker checks
    that the file it locked is still the one on disk (another run may have
    removed it between open and lock).
    """

    def __init__(self, path: Path, target: Path):
        self.path = path
        self.target = target
        self.fd: int | None = None

    def acquire(self) -> None:
        while True:
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as exc:
                raise OutputError(
                    f"cannot write beside {str(self.target)!r}: {_why(exc)}"
                ) from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                os.close(fd)
                raise OutputError(
                    f"another spiralid run is writing to {str(self.target)!r}; "
                    "wait for it to finish or choose another output"
                ) from None
            try:
                same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                self.fd = fd
                return
            os.close(fd)  # removed by its previous holder: lock the new one

    def release(self) -> None:
        if self.fd is None:
            return
        with contextlib.suppress(OSError):
            os.unlink(self.path)
        os.close(self.fd)
        self.fd = None


class _Staged:
    """A context manager that opens on entry and discards what is left
    uncommitted on exit (an error, Ctrl-C)."""

    path: Path | None = None

    def open(self):
        raise NotImplementedError

    def close(self) -> None:
        raise NotImplementedError

    def __enter__(self):
        if self.path is None:
            self.open()
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class OutputFolder(_Staged):
    """A target folder written atomically (a context manager).

    Entering checks the target (new, or empty, or ``force``), takes the lock
    beside it, tests that the target can be written and creates the staging
    folder :attr:`path`; write everything there, then call :meth:`commit`.
    Leaving without a commit (an error, Ctrl-C) removes the staging folder,
    the lock and any parent folders it created.

    Parameters
    ----------
    target : path-like
        The folder the files should end up in.
    force : bool
        Allow a non-empty target; only the files written are replaced.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> root = pathlib.Path(tempfile.mkdtemp())
    >>> with OutputFolder(root / "out") as folder:
    ...     _ = (folder.path / "a.txt").write_text("done")
    ...     written = folder.commit()
    >>> [p.name for p in written], sorted(p.name for p in root.iterdir())
    (['a.txt'], ['out'])
    """

    def __init__(self, target: str | os.PathLike, force: bool = False):
        self.target = Path(os.path.abspath(target))
        self.force = bool(force)
        self.path: Path | None = None
        self._lock: _Lock | None = None
        self._created: list[Path] = []
        self._committed = False

    # -- opening ----------------------------------------------------------------

    def _check_target(self) -> None:
        t = self.target
        if t.exists() and not t.is_dir():
            raise OutputError(f"output {str(t)!r} is a file, not a folder")
        if t.is_dir() and any(t.iterdir()) and not self.force:
            raise OutputError(
                f"output folder {str(t)!r} is not empty; choose another or pass "
                "--force to replace the files this command writes there"
            )

    def open(self) -> OutputFolder:
        t = self.target
        self._check_target()
        try:
            # Ctrl-C waits until the lock, the folders and the staging folder
            # are all made or all undone: one arriving between creating a
            # file and recording it would leave it behind.
            with _signals_deferred():
                self._created = _make_parents(t.parent)
                self._open_staging()
        except BaseException:
            self.close()
            raise
        return self

    def _open_staging(self) -> None:
        t = self.target
        self._lock = _Lock(t.parent / f"{_LOCK}{t.name}", t)
        self._lock.acquire()
        # Checked again under the lock: a run that finished meanwhile
        # has filled the target.
        self._check_target()
        _note_stale(t.parent)
        if t.is_dir():
            self._probe(t)
        try:
            self.path = Path(
                tempfile.mkdtemp(prefix=f"{_staging_prefix()}{t.name}-", dir=t.parent)
            )
        except OSError as exc:
            raise OutputError(f"cannot write beside {str(t)!r}: {_why(exc)}") from None

    def _probe(self, folder: Path) -> None:
        try:
            fd, name = tempfile.mkstemp(prefix=_staging_prefix(), dir=folder)
        except OSError as exc:
            raise OutputError(
                f"output folder {str(folder)!r} is not writable: {_why(exc)}"
            ) from None
        os.close(fd)
        os.unlink(name)

    # -- committing ---------------------------------------------------------------

    def commit(self, last: str | None = None, sets: str | None = None) -> list[Path]:
        """Move the staged files into the target; return their final paths.

        `last` names a file moved after all others (e.g. ``report.html``), so
        that its presence means the rest is there.

        `sets` is a glob pattern of the numbered folders the command writes
        as many of as its result holds (``"point-[0-9]*"``). With ``force``,
        those an earlier run left in the target that this commit does not
        write again lose the files of the names the new ones hold, and go
        once empty: a smaller result would otherwise leave the earlier one's
        surplus beside it. Anything else in them (the user's) stays.
        """
        if self.path is None or self._committed:
            raise RuntimeError("commit() needs an open, uncommitted OutputFolder")
        t = self.target
        names = sorted(p.name for p in self.path.iterdir())
        if last in names:
            names.remove(last)
            names.append(last)
        for name in names:
            if (self.path / name).is_dir():
                _publish_mode(self.path / name, directory=True)
        _publish_mode(self.path, directory=True)
        with _signals_deferred():
            try:
                if not t.exists():
                    os.rename(self.path, t)
                else:
                    # Listed before the staged folders move out.
                    surplus = _surplus(self.path, t, sets)
                    for name in names:
                        if name == last:
                            _clear(*surplus)
                        _replace(self.path / name, t / name)
                    if last not in names:
                        _clear(*surplus)
            except OSError as exc:
                raise OutputError(
                    f"cannot move the results into {str(t)!r}: {_why(exc)}"
                ) from None
            self._committed = True
            self.close()
        return [t / name for name in names]

    def close(self) -> None:
        """Discard an uncommitted staging folder; release the lock."""
        if self.path is not None and self.path.exists():
            shutil.rmtree(self.path, ignore_errors=True)
        self.path = None
        if self._lock is not None:
            self._lock.release()
            self._lock = None
        if not self._committed:
            _remove_empty(self._created)
        self._created = []


class OutputFile(_Staged):
    """A target file written atomically (a context manager).

    Entering checks the target (new unless ``force``), creates its missing
    folders and a temporary file beside it (:attr:`path`), which proves the
    folder writable before any computation; write the content there, then
    :meth:`commit`. Without ``force`` the commit is a hard link, which fails
    if the target appeared meanwhile, so a file someone else created is never
    replaced. Leaving without a commit removes the temporary file and the
    folders created.
    """

    def __init__(self, target: str | os.PathLike, force: bool = False):
        self.target = Path(os.path.abspath(target))
        self.force = bool(force)
        self.path: Path | None = None
        self._created: list[Path] = []

    def _refuse_existing(self) -> None:
        raise OutputError(f"{str(self.target)!r} exists; pass --force to overwrite it")

    def open(self) -> OutputFile:
        t = self.target
        if t.is_dir():
            raise OutputError(f"output {str(t)!r} is a folder, not a file")
        if t.exists() and not self.force:
            self._refuse_existing()
        self._created = _make_parents(t.parent)
        if not self._created:
            _note_stale(t.parent)
        try:
            fd, tmp = tempfile.mkstemp(
                prefix=_staging_prefix(), suffix=t.suffix, dir=t.parent
            )
        except OSError as exc:
            self.close()
            raise OutputError(f"cannot write {str(t)!r}: {_why(exc)}") from None
        os.close(fd)
        self.path = Path(tmp)
        return self

    def commit(self) -> Path:
        """Move the written temporary file into place; return the target."""
        if self.path is None:
            raise RuntimeError("commit() needs an open OutputFile")
        _publish_mode(self.path, directory=False)
        with _signals_deferred():
            try:
                if self.force:
                    os.replace(self.path, self.target)
                else:
                    os.link(self.path, self.target)
                    os.unlink(self.path)
            except FileExistsError:
                self.close()
                self._refuse_existing()
            except OSError as exc:
                self.close()
                raise OutputError(
                    f"cannot write {str(self.target)!r}: {_why(exc)}"
                ) from None
            self.path = None
            self._created = []
        return self.target

    def close(self) -> None:
        """Discard an uncommitted temporary file and the folders created."""
        if self.path is not None:
            with contextlib.suppress(OSError):
                self.path.unlink()
            self.path = None
        _remove_empty(self._created)
        self._created = []
