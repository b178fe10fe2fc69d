"""
Several sensors, one set of modes
=================================

The rig's four sensors (hub angle, hub velocity, end-point acceleration and
tip deflection) are driven by one torque and share the structure's modes.
``identify`` on a record of several outputs fits one denominator to all of
them: the spiral search over the shared modes, every output's numerator
projected out, each output weighted by its noise level. The hub angle
integrates twice (the rigid body) and the hub velocity once: each output's
known integrators are its own, outside the shared poles.

This page fits all four at once, validates each, and draws the
stabilisation diagram over the model orders, which is how modal analysts
tell a structure's modes from the poles a model spends on noise.
"""

import matplotlib.pyplot as plt

import spiralid as sid
from spiralid.sysid import plots

# %%
# The record
# ----------
# The paper's experiment on the default rig, every sensor at once.
rig = sid.FlexibleManipulator()
record = sid.fms.paper_experiment().run(rig, rng=0)
names = ["hub_angle", "hub_velocity", "end_acceleration", "tip_deflection"]
data = record.iodata(names)
est, val = data.split(2 / 3)
print(data.output_label)
print("FEM modes (Hz):", rig.modes(3).round(4))

# %%
# One denominator for every sensor
# --------------------------------
# ``arx.na`` counts the shared poles; the hub angle's two integrators and
# the hub velocity's one are outside them.
model = sid.identify(est, sid.ARX(10, 10, 1), rng=0, integrator=(2, 1, 0, 0))
print(model.modes)

# %%
# Each sensor's fit on the validation third, and the joint fit.
report = sid.validate(model, val, warmup=est)
print(report.summary(modes=False))

# %%
# The stabilisation diagram
# -------------------------
# Orders 4 to 12 on the acceleration and the tip deflection: a mode that
# comes back at the next order within 1 % in frequency and 5 % in damping is
# marked stable.
pair = record.iodata(["end_acceleration", "tip_deflection"]).split(2 / 3)[0]
diagram = sid.sysid.stabilisation(pair, range(4, 13, 2), nk=1, rng=0, max_nfev=3000)
print("stable at 3 or more orders (Hz):", diagram.stable_modes(3).round(2))
plt.figure(plots.plot_stabilisation(diagram, pair))
plt.show()
