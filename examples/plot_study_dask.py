"""
A small study on Dask
=====================

``spiralid study`` asks where the paper's claim (Eb-SDA ends below SDA)
holds: it runs every optimiser on every *reading* of the paper's cost (a
record, a predictor, a parametrisation) with many seeds, on a Dask cluster,
and commits each finished run to a SQLite store, so that a study that is
stopped loses nothing and a rerun computes only what is missing. This page
does the same from Python with :mod:`spiralid.study`, on a tiny
specification: the shipped robot arm, the free run from rest, both
parametrisations, SDA and Eb-SDA, 5 seeds of 2,000 evaluations with 20
points (the default study runs 20 seeds of 20,000 evaluations with 50
points over 12 readings), with least squares and output error beside them.
The numbers are those of that reduced budget.

On the command line the same study is::

    spiralid study tiny.toml --out tiny-study --workers 2
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt

from spiralid.report.study_figures import study_figures
from spiralid.report.study_output import study_summary
from spiralid.study import ResultStore, analyse, parse_spec, run_study

# %%
# The specification
# -----------------
# A TOML document; ``spiralid study --show-default`` prints the default one
# with every key explained. Unknown keys or methods, an empty grid or
# ``seeds < 1`` are refused before any run starts.
SPEC = """
[study]
seeds = 5           # seeds 0..4
budget = 2000       # cost evaluations of every run
points = 20         # search points
na = 8
nb = 8
nk = 0
baselines = ["ls", "oe"]

[grid]
predictors = ["simulation-rest"]
parametrizations = ["coefficients", "reflection"]

[[data]]
name = "arm"
kind = "arm"        # the DaISy robot arm shipped with spiralid
ts = 0.01

[[optimizer]]
label = "SDA"
method = "sda"

[[optimizer]]
label = "Eb-SDA"
method = "ebsda"
"""
spec = parse_spec(SPEC)
print(spec.n_runs, "runs:", len(spec.seeds), "seeds x 2 optimisers x 2 readings + 2")

# %%
# Running it on Dask
# ------------------
# :func:`~spiralid.study.run_study` takes an ``engine``: ``"dask"`` (the
# command's default), ``"processes"`` (a process pool) or ``"local"`` (this
# process). With ``engine="dask"`` and no ``scheduler`` it starts a
# ``LocalCluster`` of ``workers`` single-threaded worker processes; a
# ``scheduler`` address uses a cluster that is already running, such as::
#
#     spiralid study tiny.toml --scheduler tcp://host:8786
#
# Worker processes are heavy for a documentation build, so this page starts
# a small Dask cluster inside this process (one worker, two threads) and
# hands its address to ``run_study``. If Dask's ``distributed`` package is
# not installed (``pip install "spiralid[study]"`` installs it), the same
# study runs in this process without Dask; the results are the same, as
# each run draws from its own seeded generator.
store = Path(tempfile.mkdtemp(prefix="spiralid-study-")) / "study.sqlite"
try:
    from distributed import LocalCluster
except ImportError:
    LocalCluster = None

if LocalCluster is not None:
    with LocalCluster(
        n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
    ) as cluster:
        outcome = run_study(
            spec, store, engine="dask", scheduler=cluster.scheduler_address
        )
else:
    outcome = run_study(spec, store, engine="local")
print(
    f"engine: {'dask' if LocalCluster else 'local'}; "
    f"computed {outcome.computed}, reused {outcome.reused}, "
    f"failed {len(outcome.failures)} of {outcome.total}"
)

# %%
# Resuming
# --------
# Every finished run is in the store. Running the same specification on the
# same store again computes nothing: this is how a killed study resumes.
again = run_study(spec, store, engine="local")
print(f"second run: computed {again.computed}, reused {again.reused}")

# %%
# The analysis
# ------------
# :func:`~spiralid.study.analyse` groups the stored rows by reading and tests
# the claim per reading with the rank-sum test, the A12 effect size and
# Holm's correction over the readings, at the final budget and at a ladder
# of smaller budgets read from the stored convergence histories.
# ``spiralid study-report`` writes the same as ``report.html``.
with ResultStore.open(store, readonly=True) as db:
    rows = db.rows()
results = analyse(rows, spec)
print(study_summary(results))

# %%
# Figures
# -------
# :func:`spiralid.report.study_figures.study_figures` returns the report's
# figures as ``Figure`` objects that pyplot does not track;
# ``plt.figure(fig)`` hands each to pyplot. First, the convergence bands of
# every configuration per reading:
figures = study_figures(results)
print(sorted(figures))
plt.figure(figures["study_convergence"])

# %%
# Then the anytime view: per reading, the fraction of runs below a cost
# target against evaluations.
plt.figure(figures["study_anytime"])
plt.show()
