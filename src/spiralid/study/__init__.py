"""Studies at scale: every reading of the paper's cost, many seeds, on Dask.

A study (:mod:`~spiralid.study.spec`, a TOML file) crosses records,
predictors and parametrisations with optimiser configurations and seeds.
:func:`run_study` runs it on Dask (:mod:`~spiralid.study.runner`) and commits
each finished run to a SQLite store (:mod:`~spiralid.study.store`), so a
killed study resumes without losing or recomputing anything;
:func:`analyse` (:mod:`~spiralid.study.analysis`) tests the paper's claim per
reading with the statistics of :mod:`~spiralid.study.statistics`.
"""

from .analysis import CLAIM, StudyResults, analyse
from .runner import ENGINES, StudyRun, execute, run_study
from .spec import DEFAULT_SPEC, PREDICTORS, StudySpec, load_spec, parse_spec
from .statistics import a12, holm, rank_sum
from .store import ResultStore, StoreLockedError
from .tasks import Task, load_records, reproducible_part, run_task, study_tasks

__all__ = [
    "CLAIM",
    "DEFAULT_SPEC",
    "ENGINES",
    "PREDICTORS",
    "ResultStore",
    "StoreLockedError",
    "StudyResults",
    "StudyRun",
    "StudySpec",
    "Task",
    "a12",
    "analyse",
    "execute",
    "holm",
    "load_records",
    "load_spec",
    "parse_spec",
    "rank_sum",
    "reproducible_part",
    "run_study",
    "run_task",
    "study_tasks",
]
