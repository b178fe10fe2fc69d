"""
The hub angle: known integrators
================================

The rig's hub angle is the integral of the hub velocity, so its transfer
function from the torque has a pole at ``z = 1``; the hub velocity in turn
integrates the torque less a tiny viscous friction, a second pole at
``z = 0.9999997``. A method that must find those poles itself stops at its
stability bound, or, under the default stability margin (every time
constant at most the record's length), fits them badly, and its free run
drifts. ``identify(..., integrator=k)`` says that ``k`` poles at ``z = 1``
are known: the method estimates the other poles and the numerator, and the
model is composed back with the integrators. It needs the simulation error
from rest (the default).

This page uses the paper's ARX(8, 8, 0), where ``na = 8`` counts the
integrators (so 8 - k poles are estimated), on the simulated rig's bang-bang
record with noise seed 0, as the README's table "Which of the rig's outputs
need it" does for one of its rows.
"""

import matplotlib.pyplot as plt

import spiralid as sid
from spiralid.fms import paper_experiment
from spiralid.sysid import plots

# %%
# The record
# ----------
# The paper's experiment on the default rig: a bang-bang torque, 3,000
# samples at 500 Hz. The hub angle comes from the encoder.
record = paper_experiment().run(sid.FlexibleManipulator(), rng=0)
data = record.iodata("hub_angle")
est, val = data.split(2 / 3)
arx = sid.ARX(8, 8, 0)
print(data.output_label, data.n, "samples at", 1 / data.ts, "Hz;", arx)

# %%
# With and without the integrator
# -------------------------------
# Least squares, output error and the default ``spiral`` method, each with
# no, one and two known integrators, at their default stability margin. The
# validation runs each model over the whole record and scores the last third.
# With one integrator, the second (the rigid body's, at 0.9999997) is slower
# than the margin of oe and spiral allows; with two, both are known.
runs = {}
for method in ("ls", "oe", "spiral"):
    for integrator in (0, 1, 2):
        model = sid.identify(est, arx, method=method, rng=0, integrator=integrator)
        label = method + ("", " + integrator", " + 2 integrators")[integrator]
        runs[label] = sid.validate(model, val, warmup=est, label=label)

print(f"{'method':<22} {'fit %':>7} {'stable':>7} {'max |pole|':>14}")
for label, rep in runs.items():
    radius = sid.sysid.format_pole_radius(rep.max_pole_radius)
    print(f"{label:<22} {rep.fit_percent:7.1f} {rep.stable!s:>7} {radius:>14}")

# %%
# With the integrators, ``stable`` and the largest pole radius are about the
# other poles: the model is marginally stable by design, and its validation
# summary says so.
print(runs["spiral + 2 integrators"].summary())

# %%
# Figure
# ------
# The free runs of output error and ``spiral`` with none, one and two
# integrators, on the validation third.
# :func:`~spiralid.sysid.plots.plot_validations` returns ``Figure`` objects
# that pyplot does not track; ``plt.figure(fig)`` hands one to pyplot.
shown = ["oe", "oe + 2 integrators", "spiral", "spiral + integrator"]
shown.append("spiral + 2 integrators")
overlay = plots.plot_validations({label: runs[label] for label in shown})
plt.figure(overlay["time"])
plt.show()
