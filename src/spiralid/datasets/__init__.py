"""Example data shipped with spiralid (see ``datasets/README.md`` for provenance).

:func:`robot_arm` is the DaISy 96-009 flexible robot arm record, a real
torque-to-acceleration record of a flexible structure, so examples and tests
run on a fresh clone without any download. ``spiralid identify robot_arm``
reads it by name.
"""

from __future__ import annotations

from spiralid.datasets.files import read_record
from spiralid.datasets.shipped import NAMES, load, robot_arm

__all__ = ["NAMES", "load", "read_record", "robot_arm"]
