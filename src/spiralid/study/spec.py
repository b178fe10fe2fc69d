"""A study specification: which readings, optimisers and seeds to run.

A study crosses every *reading* of the paper's cost (a data record, a
predictor and a parametrisation) with every optimiser configuration and every
seed; least squares and output error run once per record and predictor beside
them. The specification is a TOML file; :data:`DEFAULT_SPEC` (``default.toml``
beside this module) is the paper's grid.

Every check runs in :func:`load_spec` / :func:`parse_spec`, before any work:
an unknown key, an unknown method, an empty grid, ``seeds < 1`` or a data
file that cannot be read is a one-line :class:`ValueError`.
"""

from __future__ import annotations

import hashlib
import json
import tomllib
from dataclasses import dataclass, field
from math import inf
from pathlib import Path
from typing import Any

__all__ = [
    "DEFAULT_SPEC",
    "PREDICTORS",
    "DataSpec",
    "OptimizerSpec",
    "StudySpec",
    "load_spec",
    "parse_spec",
]

DEFAULT_SPEC = Path(__file__).with_name("default.toml")

# A reading's predictor: the name in a specification, and the `predictor` and
# `initial` of spiralid.sysid.identify it stands for.
PREDICTORS: dict[str, tuple[str, str]] = {
    "simulation-rest": ("simulation", "rest"),
    "simulation-measured": ("simulation", "measured"),
    "one-step": ("one-step", "rest"),
}
_DATA_KINDS = ("rig", "arm", "csv")
_STUDY_KEYS = ("seeds", "budget", "points", "na", "nb", "nk", "fraction", "baselines")
_GRID_KEYS = ("predictors", "parametrizations")
_DATA_KEYS = {
    "rig": ("name", "kind", "output", "noise_seed", "rig", "all_outputs"),
    "arm": ("name", "kind", "ts"),
    "csv": ("name", "kind", "path", "input", "output", "ts", "detrend"),
}
_OPTIMIZER_KEYS = ("label", "method", "refine", "gain_scale", "safe_start", "options")
# The deterministic baselines beside every metaheuristic, method -> the
# label every table and figure gives it: the one list of them.
BASELINES = {"ls": "LS", "oe": "OE"}
_BASELINES = tuple(BASELINES)


@dataclass(frozen=True)
class DataSpec:
    """One record of the study: its name, kind and how to obtain it.

    Attributes
    ----------
    name, kind : str
    settings : dict
        The record's other keys in the specification; ``all_outputs`` only
        when true.
    """

    name: str
    kind: str
    settings: dict = field(default_factory=dict)

    @property
    def all_outputs(self) -> bool:
        """A rig record whose modes the study also identifies from every
        sensor of the same run (:mod:`spiralid.study.modes`)."""
        return bool(self.settings.get("all_outputs", False))

    def rig(self):
        """The :class:`~spiralid.fms.FlexibleManipulator` a rig record
        simulates."""
        from spiralid.fms import FlexibleManipulator

        return FlexibleManipulator(**self.settings.get("rig", {}))

    def load(self):
        """The record as an :class:`~spiralid.sysid.IOData`."""
        from spiralid.datasets import read_record

        s = self.settings
        if self.kind == "rig":
            from spiralid.fms import paper_experiment

            rec = paper_experiment().run(self.rig(), rng=s.get("noise_seed", 0))
            return rec.iodata(s.get("output", "end_acceleration"))
        if self.kind == "arm":
            from spiralid.datasets import robot_arm

            return robot_arm(ts=s.get("ts", 0.01))
        data = read_record(s["path"], s.get("input"), s.get("output"), s.get("ts"))
        return data.detrend() if s.get("detrend", False) else data


@dataclass(frozen=True)
class OptimizerSpec:
    """One optimiser configuration: a label, an identify method and options."""

    label: str
    method: str
    refine: bool = False
    gain_scale: float = 1.0
    safe_start: bool | None = None
    options: dict = field(default_factory=dict)


@dataclass(frozen=True)
class StudySpec:
    """A parsed, checked study specification (see the module docstring).

    Attributes
    ----------
    data : tuple of DataSpec
    predictors, parametrizations : tuple of str
        The reading axes crossed with `data`.
    optimizers : tuple of OptimizerSpec
    seeds : tuple of int
    budget, points : int
        Cost evaluations and search points of every run.
    na, nb, nk : int
        The ARX structure, eq. (6).
    fraction : float
        Estimation share of each record.
    baselines : tuple of str
        Deterministic baselines run once per record and predictor.
    source : str
        The specification's text, kept with the results.
    """

    data: tuple[DataSpec, ...]
    predictors: tuple[str, ...]
    parametrizations: tuple[str, ...]
    optimizers: tuple[OptimizerSpec, ...]
    seeds: tuple[int, ...]
    budget: int = 20_000
    points: int = 50
    na: int = 8
    nb: int = 8
    nk: int = 0
    fraction: float = 2 / 3
    baselines: tuple[str, ...] = _BASELINES
    source: str = ""

    @property
    def n_runs(self) -> int:
        """Runs of the study, baselines included (as many as
        :func:`~spiralid.study.study_tasks` lists)."""
        searches = len(self.parametrizations) * len(self.optimizers) * len(self.seeds)
        return len(self.data) * len(self.predictors) * (len(self.baselines) + searches)

    def digest(self) -> str:
        """A hash of everything that decides the runs' results."""
        payload = {
            "data": [(d.name, d.kind, d.settings) for d in self.data],
            "predictors": self.predictors,
            "parametrizations": self.parametrizations,
            "optimizers": [
                (o.label, o.method, o.refine, o.gain_scale, o.safe_start, o.options)
                for o in self.optimizers
            ],
            "seeds": self.seeds,
            "budget": self.budget,
            "points": self.points,
            "arx": (self.na, self.nb, self.nk),
            "fraction": self.fraction,
            "baselines": self.baselines,
        }
        text = json.dumps(payload, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()


def load_spec(path: str | Path | None = None) -> StudySpec:
    """Read and check the TOML study specification at `path` (default: the
    paper's grid).

    Relative data paths are resolved against the specification's folder.
    The records themselves are read by :func:`spiralid.study.load_records`,
    which the runner calls before any run starts.
    """
    file = DEFAULT_SPEC if path is None else Path(path)
    try:
        text = file.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise ValueError(f"study specification {str(file)!r} does not exist") from None
    except UnicodeDecodeError:
        raise ValueError(
            f"study specification {str(file)!r} is not UTF-8 text (TOML files are)"
        ) from None
    except OSError as exc:
        raise ValueError(
            f"study specification {str(file)!r} cannot be read: {exc.strerror or exc}"
        ) from None
    return parse_spec(text, base=file.parent, where=str(file))


def _fail(where: str, message: str):
    raise ValueError(f"{where}: {message}")


def _check_keys(table: dict, allowed, where: str, what: str) -> None:
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        _fail(where, f"unknown key {unknown[0]!r} in {what}; allowed: {list(allowed)}")


def _int(value, where: str, name: str, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        _fail(where, f"`{name}` must be an integer >= {low}; got {value!r}")
    return value


def _fraction(value, where: str) -> float:
    if isinstance(value, str) and value.count("/") == 1:
        num, den = value.split("/")
        try:
            value = int(num) / int(den)
        except (ValueError, ZeroDivisionError):
            _fail(where, f"`fraction` must be a number in (0, 1); got {value!r}")
    if isinstance(value, bool) or not isinstance(value, int | float):
        _fail(where, f"`fraction` must be a number in (0, 1); got {value!r}")
    if not 0 < value < 1:
        _fail(where, f"`fraction` must be a number in (0, 1); got {value!r}")
    return float(value)


def _names(value, allowed, where: str, name: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not value:
        _fail(where, f"`{name}` must be a non-empty list; got {value!r}")
    for v in value:
        if v not in allowed:
            _fail(where, f"unknown {name[:-1]} {v!r}; known: {list(allowed)}")
    if len(set(value)) != len(value):
        _fail(where, f"`{name}` lists an entry twice: {value!r}")
    return tuple(value)


def _baselines(value, where: str) -> tuple[str, ...]:
    # An empty list is allowed: a study of the optimisers alone.
    return () if value == [] else _names(value, _BASELINES, where, "baselines")


def _data(entry: Any, base: Path | None, where: str) -> DataSpec:
    if not isinstance(entry, dict):
        _fail(where, f"each [[data]] must be a table; got {entry!r}")
    kind = entry.get("kind")
    if kind not in _DATA_KINDS:
        _fail(
            where, f"[[data]] `kind` must be one of {list(_DATA_KINDS)}; got {kind!r}"
        )
    if "all_outputs" in entry and kind != "rig":
        # Before the unknown-key check, to say why rather than only "unknown".
        _fail(
            where,
            f"[[data]] of kind {kind!r}: `all_outputs` applies to kind 'rig' "
            "only (the simulated rig's four sensors of one run)",
        )
    _check_keys(entry, _DATA_KEYS[kind], where, f"[[data]] of kind {kind!r}")
    name = entry.get("name", kind)
    if not isinstance(name, str) or not name:
        _fail(where, f"[[data]] `name` must be a non-empty string; got {name!r}")
    settings = {k: v for k, v in entry.items() if k not in ("name", "kind")}
    ts = settings.get("ts", 1.0)
    if isinstance(ts, bool) or not isinstance(ts, int | float) or not 0 < ts < inf:
        # Here, naming the record: IOData would blame its own `ts` argument.
        _fail(where, f"[[data]] {name!r}: `ts` must be a number > 0; got {ts!r}")
    if kind == "csv":
        if "path" not in settings:
            _fail(where, f"[[data]] {name!r} of kind 'csv' needs a `path`")
        path = Path(settings["path"])
        if base is not None and not path.is_absolute():
            path = base / path
        settings["path"] = str(path.resolve())
    if kind == "rig" and not isinstance(settings.get("rig", {}), dict):
        _fail(where, f"[[data]] {name!r}: `rig` must be a table of rig settings")
    if not isinstance(settings.get("all_outputs", False), bool):
        _fail(
            where,
            f"[[data]] {name!r}: `all_outputs` must be true or false; "
            f"got {settings['all_outputs']!r}",
        )
    if not settings.get("all_outputs", True):
        # Off is the default: a spec that says so hashes as one that does not.
        del settings["all_outputs"]
    return DataSpec(name, kind, settings)


def _optimizer(entry: Any, methods, where: str) -> OptimizerSpec:
    if not isinstance(entry, dict):
        _fail(where, f"each [[optimizer]] must be a table; got {entry!r}")
    _check_keys(entry, _OPTIMIZER_KEYS, where, "[[optimizer]]")
    method = entry.get("method")
    if method not in methods:
        _fail(where, f"unknown method {method!r} in [[optimizer]]; known: {methods}")
    label = entry.get("label", method)
    if not isinstance(label, str) or not label:
        _fail(where, f"[[optimizer]] `label` must be a non-empty string; got {label!r}")
    refine = entry.get("refine", False)
    safe_start = entry.get("safe_start")
    for name, value in (("refine", refine), ("safe_start", safe_start)):
        if value is not None and not isinstance(value, bool):
            _fail(where, f"[[optimizer]] {label!r}: `{name}` must be true or false")
    scale = entry.get("gain_scale", 1.0)
    if isinstance(scale, bool) or not isinstance(scale, int | float) or scale <= 0:
        _fail(where, f"[[optimizer]] {label!r}: `gain_scale` must be a number > 0")
    options = entry.get("options", {})
    if not isinstance(options, dict):
        _fail(where, f"[[optimizer]] {label!r}: `options` must be a table")
    from spiralid.sysid.estimation.core.identify import check_method_options

    try:
        # Checked here, before any run, as identify() would check each.
        check_method_options(method, options)
    except (TypeError, ValueError) as exc:
        _fail(where, f"[[optimizer]] {label!r}: {exc}")
    return OptimizerSpec(label, method, refine, float(scale), safe_start, dict(options))


def _search_methods() -> list[str]:
    from spiralid.sysid import METHODS

    return [name for name, m in METHODS.items() if m.search]


def parse_spec(
    text: str, *, base: Path | None = None, where: str = "study specification"
) -> StudySpec:
    """Parse and check a study specification given as TOML text.

    Parameters
    ----------
    text : str
        The TOML document (see ``default.toml`` for every key).
    base : Path, optional
        Folder that relative data paths are resolved against.
    where : str
        How error messages name the specification.

    Returns
    -------
    StudySpec
    """
    from spiralid.sysid import PARAMETRIZATIONS

    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        _fail(where, f"not valid TOML: {exc}")
    _check_keys(doc, ("study", "grid", "data", "optimizer"), where, "the top level")
    study = doc.get("study", {})
    grid = doc.get("grid", {})
    if not isinstance(study, dict) or not isinstance(grid, dict):
        _fail(where, "[study] and [grid] must be tables")
    _check_keys(study, _STUDY_KEYS, where, "[study]")
    _check_keys(grid, _GRID_KEYS, where, "[grid]")

    seeds = study.get("seeds", 20)
    if isinstance(seeds, list):
        if not seeds:
            _fail(where, "`seeds` must be >= 1 or a non-empty list of seeds")
        seed_list = tuple(_int(s, where, "seeds", 0) for s in seeds)
        if len(set(seed_list)) != len(seed_list):
            _fail(where, f"`seeds` lists a seed twice: {seeds!r}")
    else:
        seed_list = tuple(range(_int(seeds, where, "seeds", 1)))

    entries = doc.get("data", [])
    if not isinstance(entries, list) or not entries:
        _fail(where, "the grid is empty: give at least one [[data]] record")
    data = tuple(_data(e, base, where) for e in entries)
    names = [d.name for d in data]
    if len(set(names)) != len(names):
        _fail(where, f"[[data]] names must differ; got {names}")
    optimizers = tuple(
        _optimizer(e, _search_methods(), where) for e in doc.get("optimizer", [])
    )
    if not optimizers:
        _fail(where, "the grid is empty: give at least one [[optimizer]]")
    labels = [o.label for o in optimizers]
    if len(set(labels)) != len(labels):
        _fail(where, f"[[optimizer]] labels must differ; got {labels}")

    points = _int(study.get("points", 50), where, "points", 2)
    budget = _int(study.get("budget", 20_000), where, "budget", 1)
    if budget < 2 * points:
        _fail(where, f"`budget` must be >= 2 * points = {2 * points}; got {budget}")
    spec = StudySpec(
        data=data,
        predictors=_names(
            grid.get("predictors", list(PREDICTORS)), PREDICTORS, where, "predictors"
        ),
        parametrizations=_names(
            grid.get("parametrizations", list(PARAMETRIZATIONS)),
            list(PARAMETRIZATIONS),
            where,
            "parametrizations",
        ),
        optimizers=optimizers,
        seeds=seed_list,
        budget=budget,
        points=points,
        na=_int(study.get("na", 8), where, "na", 0),
        nb=_int(study.get("nb", 8), where, "nb", 1),
        nk=_int(study.get("nk", 0), where, "nk", 0),
        fraction=_fraction(study.get("fraction", 2 / 3), where),
        baselines=_baselines(study.get("baselines", list(_BASELINES)), where),
        source=text,
    )
    return spec
