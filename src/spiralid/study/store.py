"""The result store of a study: one SQLite row per finished run.

Each row is committed in its own transaction as its run finishes, so a study
killed at any moment (Ctrl-C, SIGKILL, a power cut) keeps every run that had
finished, and a rerun of the same command computes only the rest. A store
belongs to one specification: opening it with another is refused, since its
rows would answer a different question.

A rig record with ``all_outputs`` adds its modes from every sensor, one row
per record in a table of its own (``modes``), created with the first of
them: a store without it (a study without the option, or written before it
existed) reads as one without modes.

Two processes never write one store: :meth:`ResultStore.open` takes an
exclusive ``flock`` on ``STORE.lock`` beside it (released by the kernel when
the holder exits, however it exits) and refuses with a clear error while
another study holds it.
"""

from __future__ import annotations

import fcntl
import json
import os
import sqlite3
from pathlib import Path

__all__ = ["ResultStore", "StoreLockedError"]

_COLUMNS = (
    ("key", "TEXT PRIMARY KEY"),
    ("data", "TEXT NOT NULL"),
    ("predictor", "TEXT NOT NULL"),
    ("parametrization", "TEXT"),
    ("label", "TEXT NOT NULL"),
    ("method", "TEXT NOT NULL"),
    ("seed", "INTEGER"),
    ("cost", "REAL"),
    ("fit_val", "REAL"),
    ("nfev", "INTEGER"),
    ("seconds", "REAL"),
    ("stable", "INTEGER"),
    ("model", "TEXT"),
)
_JSON = ("model",)


class StoreLockedError(ValueError):
    """Another study is writing this store."""


class ResultStore:
    """A study's SQLite store (use :meth:`open`, as a context manager).

    Parameters
    ----------
    path : path-like
        The database file; created with its folder if missing.
    digest : str
        The specification's :meth:`~spiralid.study.StudySpec.digest`.
    spec_text : str
        The specification's text, kept for the report.
    readonly : bool
        Open an existing store to read it (no lock, no writes).
    """

    def __init__(self, path, digest: str = "", spec_text: str = "", *, readonly=False):
        self.path = Path(path)
        self.readonly = readonly
        self._lock_file = None
        if readonly:
            if not self.path.is_file():
                raise ValueError(f"store {str(self.path)!r} does not exist")
            if self.path.stat().st_size == 0:
                raise ValueError(
                    f"store {str(self.path)!r} is an empty file, not a spiralid store"
                )
            uri = f"file:{self.path.resolve()}?mode=ro"
            self._db = self._connect(uri, uri=True)
            if "runs" not in self._tables():
                self.close()
                raise ValueError(
                    f"store {str(self.path)!r} is not a spiralid store: it is an "
                    "SQLite database without a table of runs"
                )
            return
        self.path.parent.mkdir(parents=True, exist_ok=True)
        lock_path = self._lock_path()
        fresh_lock = not lock_path.exists()
        self._lock()
        try:
            self._db = self._connect(str(self.path))
            self._init(digest, spec_text)
        except BaseException:
            if fresh_lock:
                # Refused (a file that is not a store, another
                # specification's store): leave nothing beside it.
                lock_path.unlink(missing_ok=True)
            self.close()
            raise

    @classmethod
    def open(cls, path, digest: str = "", spec_text: str = "", *, readonly=False):
        """Open (or create) a store; see the class docstring."""
        return cls(path, digest, spec_text, readonly=readonly)

    def _connect(self, target: str, uri: bool = False) -> sqlite3.Connection:
        try:
            db = sqlite3.connect(target, uri=uri)
            db.execute("SELECT count(*) FROM sqlite_master").fetchone()
        except sqlite3.DatabaseError as exc:
            raise ValueError(
                f"store {str(self.path)!r} is not a spiralid store: {exc}"
            ) from None
        return db

    def _tables(self) -> set[str]:
        query = "SELECT name FROM sqlite_master WHERE type = 'table'"
        return {name for (name,) in self._db.execute(query)}

    def _lock_path(self) -> Path:
        return self.path.with_name(self.path.name + ".lock")

    def _lock(self) -> None:
        lock_path = self._lock_path()
        fh = open(lock_path, "a+")  # held until close()
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            fh.seek(0)
            holder = fh.read().strip() or "another process"
            fh.close()
            raise StoreLockedError(
                f"store {str(self.path)!r} is in use by another study ({holder}); "
                "wait for it to finish or choose another --store"
            ) from None
        fh.seek(0)
        fh.truncate()
        fh.write(f"pid {os.getpid()}")
        fh.flush()
        self._lock_file = fh

    def _init(self, digest: str, spec_text: str) -> None:
        tables = self._tables()
        if tables - {"meta", "runs", "modes"}:
            # Someone else's database: adding our tables to it would be
            # writing into their file.
            raise ValueError(
                f"store {str(self.path)!r} is not a spiralid store: it is an "
                f"SQLite database of something else (tables: {sorted(tables)})"
            )
        with self._db:
            self._db.execute(
                "CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT)"
            )
            cols = ", ".join(f"{name} {kind}" for name, kind in _COLUMNS)
            self._db.execute(f"CREATE TABLE IF NOT EXISTS runs ({cols})")
        stored = self.meta().get("digest")
        if stored is None:
            with self._db:
                self._db.executemany(
                    "INSERT INTO meta VALUES (?, ?)",
                    [("digest", digest), ("spec", spec_text)],
                )
        elif stored != digest:
            raise ValueError(
                f"store {str(self.path)!r} holds a study of another specification; "
                "rerun that specification, or choose another --store"
            )

    def meta(self) -> dict:
        """The store's metadata: the specification's digest and text."""
        try:
            return dict(self._db.execute("SELECT key, value FROM meta"))
        except sqlite3.OperationalError:
            return {}

    def keys(self) -> set[str]:
        """Keys of the finished runs."""
        return {k for (k,) in self._db.execute("SELECT key FROM runs")}

    def add(self, row: dict) -> None:
        """Store one finished run, committed at once (atomically)."""
        values = [
            json.dumps(row[name]) if name in _JSON else row[name]
            for name, _ in _COLUMNS
        ]
        marks = ", ".join("?" for _ in _COLUMNS)
        with self._db:
            self._db.execute(f"INSERT OR REPLACE INTO runs VALUES ({marks})", values)

    def add_modes(self, record: str, result: dict) -> None:
        """Store the modes of `record` from every sensor, committed at once.

        Parameters
        ----------
        record : str
            The record's name in the specification.
        result : dict
            :meth:`spiralid.study.modes.SharedModesFit.to_dict`.
        """
        with self._db:
            self._db.execute(
                "CREATE TABLE IF NOT EXISTS modes "
                "(record TEXT PRIMARY KEY, result TEXT)"
            )
            self._db.execute(
                "INSERT OR REPLACE INTO modes VALUES (?, ?)",
                (record, json.dumps(result)),
            )

    def modes(self) -> dict[str, dict]:
        """The stored modes from every sensor, by record name (empty for a
        store without them)."""
        if "modes" not in self._tables():
            return {}
        query = "SELECT record, result FROM modes ORDER BY record"
        return {record: json.loads(text) for record, text in self._db.execute(query)}

    def rows(self) -> list[dict]:
        """Every stored run as a dict, in key order."""
        names = [name for name, _ in _COLUMNS]
        out = []
        for values in self._db.execute(
            f"SELECT {', '.join(names)} FROM runs ORDER BY key"
        ):
            row = dict(zip(names, values, strict=True))
            for name in _JSON:
                row[name] = None if row[name] is None else json.loads(row[name])
            row["stable"] = bool(row["stable"])
            out.append(row)
        return out

    def __len__(self) -> int:
        return self._db.execute("SELECT count(*) FROM runs").fetchone()[0]

    def close(self) -> None:
        db = getattr(self, "_db", None)
        if db is not None:
            db.close()
            self._db = None
        if self._lock_file is not None:
            self._lock_file.close()
            self._lock_file = None

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()
