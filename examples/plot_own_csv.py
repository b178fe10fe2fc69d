"""
Identify a model from your own CSV file
=======================================

The whole route from a file on disk to a validated model: write a CSV
record, read it with :meth:`spiralid.IOData.from_csv`, estimate an ARX model
with :func:`spiralid.identify` (its default method, ``"spiral"``), and judge
it on data it was not estimated on with :func:`spiralid.validate`.

So that the answer is known, the "measurement" is simulated here: a lightly
damped second-order plant (a mass on a spring, 2 Hz, damping ratio 0.05),
driven by a random two-level force and observed with noise. Replace the
first cell by your own file and the rest stays the same.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from scipy import signal

import spiralid as sid

# %%
# A record to identify
# --------------------
# The plant is continuous, ``wn^2 / (s^2 + 2 zeta wn s + wn^2)``, sampled
# every 10 ms with a zero-order hold, which is exactly an ARX(2, 2, 1)
# structure: two poles, two numerator terms, one sample of delay. The force
# switches between -1 N and 1 N at random times, and the position is
# measured with white noise of 5 % of its own standard deviation.
ts = 0.01
wn, zeta = 2 * np.pi * 2.0, 0.05
num, den, _ = signal.cont2discrete(
    ([wn**2], [1.0, 2 * zeta * wn, wn**2]), ts, method="zoh"
)
rng = np.random.default_rng(0)
n = 1500
holds = rng.integers(5, 40, size=n)  # samples each level is held
levels = rng.choice([-1.0, 1.0], size=n)
force = np.repeat(levels, holds)[:n]
position = signal.lfilter(num.ravel(), den, force)
position += 0.05 * position.std() * rng.standard_normal(n)

folder = Path(tempfile.mkdtemp(prefix="spiralid-example-"))
path = folder / "record.csv"
time_s = ts * np.arange(n)
np.savetxt(
    path,
    np.column_stack([time_s, force, position]),
    delimiter=",",
    header="time_s,force [N],position [mm]",
    comments="",
)
print(path.read_text().splitlines()[:3])

# %%
# Read it
# -------
# Columns are chosen by name; a unit in brackets in the header goes with the
# signal into every figure and table. A CSV carries no sample time, so it is
# given here (``spiralid identify`` on the command line reads the ``time_s``
# column instead).
data = sid.IOData.from_csv(path, input="force", output="position", ts=ts)
print(data.n, data.ts, data.input_label, data.output_label)

# %%
# Estimate on two thirds, validate on the last third
# --------------------------------------------------
# ``identify``'s default method is ``"spiral"``: Eb-SDA over the
# denominator's modes with the numerator projected out, polished as it goes.
# Least squares (``"ls"``) and output error (``"oe"``) run beside it: least
# squares minimises the one-step error, which noise on the output biases;
# output error minimises the free-run error, as ``spiral`` does.
est, val = data.split(2 / 3)
arx = sid.ARX(2, 2, 1)
models = {
    "spiral": sid.identify(est, arx, rng=0),
    "ls": sid.identify(est, arx, method="ls"),
    "oe": sid.identify(est, arx, method="oe"),
}
reports = {
    name: sid.validate(model, val, warmup=est, label=name)
    for name, model in models.items()
}
for name, rep in reports.items():
    modes = ", ".join(
        f"{f:.3f} Hz (damping {z:.3f})"
        for f, z in zip(rep.modes.frequency, rep.modes.damping, strict=True)
    )
    # Only lightly damped modes are listed (damping below 0.3).
    print(f"{name:>6}: validation fit {rep.fit_percent:5.1f} %, mode {modes or '-'}")
print(f"truth : mode {wn / (2 * np.pi):.3f} Hz (damping {zeta:.3f})")

# %%
# The spiral model in the form of the paper's eq. (9)-(10), and its
# validation summary (residual tests, spectra, stability).
print(models["spiral"].tf_string())
print(reports["spiral"].summary())

# %%
# Which residual the correlation tests examine is ``validate``'s
# ``residuals=`` argument; the summary above says which one it used. Both
# are asked for here: the one-step residual, the ARX model's estimate of its
# innovations (what MATLAB's ``resid`` tests), and the free-run error. The
# noise of this record was added to the output, not filtered by the plant's
# poles, so the one-step residual of even the true model is coloured noise,
# while the free-run error of a good model is the added white noise.
for residuals in ("one-step", "simulation"):
    test = sid.validate(
        models["spiral"], val, warmup=est, residuals=residuals
    ).whiteness
    print(
        f"whiteness of the {residuals} residual: p = {test.p_value:.3g}, "
        f"pass at 95 %: {test.passed[0.95]}"
    )

# %%
# Figures
# -------
# :meth:`~spiralid.Validation.plot` returns matplotlib ``Figure`` objects
# (``"time"``, ``"residuals"``, ``"spectrum"``, ``"pole_zero"``) that pyplot
# does not track; ``plt.figure(fig)`` hands one to pyplot, so that
# ``plt.show()`` (and this gallery) displays it.
figures = reports["spiral"].plot()
plt.figure(figures["time"])
plt.figure(figures["spectrum"])
plt.show()
