"""The flexible manipulator plant: a finite-element simulator of the rig.

The physical rig of the paper is not available, so :class:`FlexibleManipulator`
simulates it from physics (hub + Euler-Bernoulli beam + payload, exact
zero-order-hold sampling, encoder/tachometer/accelerometer models).
:class:`RigGreyBox` (:mod:`spiralid.fms.greybox`) is the rig as a grey box
whose physical parameters :func:`spiralid.sysid.identify` fits to a record;
:func:`rig_start_from_modes` (:mod:`spiralid.fms.greybox_start`) starts it
where its modes are a black box's.
"""

from spiralid.fms.experiment import Experiment, paper_experiment
from spiralid.fms.rig import FlexibleManipulator, Recording, nonlinear_rig
from spiralid.fms.sensors import Sensors
from spiralid.fms.signals import bang_bang, chirp, multilevel, prbs

__all__ = [
    "Experiment",
    "FlexibleManipulator",
    "Recording",
    "RigGreyBox",
    "Sensors",
    "bang_bang",
    "chirp",
    "multilevel",
    "nonlinear_rig",
    "paper_experiment",
    "prbs",
    "rig_start_from_modes",
]


def __getattr__(name: str):
    # The grey box builds on spiralid.sysid: loaded on first use, so that
    # the simulator alone stays as light to import as before.
    if name == "RigGreyBox":
        from spiralid.fms.greybox import RigGreyBox

        return RigGreyBox
    if name == "rig_start_from_modes":
        from spiralid.fms.greybox_start import rig_start_from_modes

        return rig_start_from_modes
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
