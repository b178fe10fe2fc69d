"""The flexible manipulator plant: a finite-element simulator of the rig.

The physical rig of the paper is not available, so :class:`FlexibleManipulator`
simulates it from physics (hub + Euler-Bernoulli beam + payload, exact
zero-order-hold sampling, encoder/tachometer/accelerometer models).
"""

from spiralid.fms.experiment import Experiment, paper_experiment
from spiralid.fms.rig import FlexibleManipulator, Recording, nonlinear_rig
from spiralid.fms.sensors import Sensors
from spiralid.fms.signals import bang_bang, chirp, multilevel, prbs

__all__ = [
    "Experiment",
    "FlexibleManipulator",
    "Recording",
    "Sensors",
    "bang_bang",
    "chirp",
    "multilevel",
    "nonlinear_rig",
    "paper_experiment",
    "prbs",
]
