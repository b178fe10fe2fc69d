"""
The paper's reproduction, at a reduced size
===========================================

The paper (Nasir, Ismail, Ahmad and Tokhi) identifies an ARX(8, 8, 0) model
of a flexible manipulator's end-point acceleration with SDA and with its
exponential-based variant Eb-SDA, and reports that Eb-SDA does better.
:func:`spiralid.reproduction.reproduce` runs that comparison on the simulated rig
with every search given the same budget of cost evaluations, over several
seeds, with least squares (LS) and output error (OE) beside them; it is
what ``spiralid reproduce`` runs before it writes its report.

The README's tables come from the full size (6 seeds, 20,000 evaluations and
50 points per run). To build in seconds, this page runs **3 seeds, 2,000
evaluations and 20 points per run**, and a subset of the configurations: its
numbers are those of that reduced budget, not the paper's. The same reduced
run from the command line::

    spiralid reproduce --seeds 3 --budget 2000 --points 20 --workers 1
"""

import matplotlib.pyplot as plt

from spiralid.report import figures as report_figures
from spiralid.report import summary_text
from spiralid.reproduction import CONFIGURATIONS, reproduce

# %%
# The configurations
# ------------------
# :data:`~spiralid.reproduction.CONFIGURATIONS` lists every arm of the comparison:
# the paper's SDA and Eb-SDA over the raw coefficients (with the stability
# penalty), the same searches over reflection coefficients (stable by
# construction), Eb-SDA polished by the output-error method, Eb-SDA with the
# cost's unstated gain scaled, SciPy's differential evolution (DE) and the
# recommended ``spiral`` method. This page keeps all but the two gain
# scalings.
for c in CONFIGURATIONS:
    print(f"{c.label:<22} method={c.method!r:<9} parametrization={c.parametrization!r}")
kept = [c for c in CONFIGURATIONS if c.gain_scale == 1.0]

# %%
# Run it
# ------
# ``workers=1`` runs every identification in this process (the default uses
# a process pool of one worker per core). The record is the simulated rig's
# bang-bang experiment: torque in, end-point acceleration out, 3,000 samples
# at 500 Hz, the first 2,000 estimating and the last 1,000 validating.
rep = reproduce(seeds=3, max_nfev=2000, n_points=20, configurations=kept, workers=1)
print(summary_text(rep))

# %%
# The paper's claim is that Eb-SDA ends at a lower cost than SDA. The
# Wilcoxon rank-sum test over the seeds, as the report prints it (with three
# seeds no difference can reach a small p-value: the smallest two-sided
# p-value of the exact test with 3 against 3 is 0.1):
test = rep.ranksum("Eb-SDA", "SDA")
median = {label: rep.statistics(label)["cost_median"] for label in ("Eb-SDA", "SDA")}
print(
    f"median cost Eb-SDA {median['Eb-SDA']:.4g}, SDA {median['SDA']:.4g}; "
    f"two-sided p = {test['p_two_sided']:.3g}"
)
for label in ("LS", "OE"):
    print(f"{label}: estimation cost {rep.best(label).cost:.4g}")

# %%
# Figures
# -------
# :mod:`spiralid.report.figures` draws the report's figures from the
# :class:`~spiralid.reproduction.Reproduction`. They are ``Figure`` objects that
# pyplot does not track; ``plt.figure(fig)`` hands each to pyplot so that
# the gallery shows it.
#
# Figure 6a of the paper: the best cost against iteration and against wall
# time, median and interquartile band over the seeds.
plt.figure(report_figures.convergence(rep))

# %%
# Figures 7a-b: the validation third, measured against the best SDA, Eb-SDA
# and output-error models (each run freely over the whole record).
plt.figure(report_figures.validation_response(rep))

# %%
# Every run's estimation cost and validation fit per configuration, with the
# least-squares and output-error results as horizontal lines.
plt.figure(report_figures.distributions(rep))
plt.show()
