"""Example data shipped with spiralid (see ``datasets/README.md`` for provenance).

:func:`robot_arm` is the DaISy 96-009 flexible robot arm record, a real
torque-to-acceleration record of a flexible structure, so examples and tests
run on a fresh clone without any download. :func:`cascaded_tanks` holds the
two measured records of the Cascaded Tanks nonlinear benchmark. ``spiralid
identify robot_arm`` (or ``cascaded_tanks``, ``cascaded_tanks_test``) reads
one by name.
"""

from __future__ import annotations

from spiralid.datasets.files import read_record
from spiralid.datasets.shipped import (
    CASCADED_TANKS_PUBLISHED,
    NAMES,
    cascaded_tanks,
    load,
    robot_arm,
)

__all__ = [
    "CASCADED_TANKS_PUBLISHED",
    "NAMES",
    "cascaded_tanks",
    "load",
    "read_record",
    "robot_arm",
]
