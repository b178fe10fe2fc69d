"""General-purpose spiral dynamic optimisers (SDA, Eb-SDA, linear adaptive SDA).

Knows nothing of system identification. See :func:`minimize`.
"""

from spiralid.optim import testfunctions
from spiralid.optim.rotation import planes, rotate, rotation_matrix
from spiralid.optim.rules import (
    ConstantSpiral,
    ExponentialSpiral,
    LinearSpiral,
    SpiralRule,
    exponential_rule,
)
from spiralid.optim.spiral import SpiralResult, SpiralSearch, minimize

__all__ = [
    "ConstantSpiral",
    "ExponentialSpiral",
    "LinearSpiral",
    "SpiralResult",
    "SpiralRule",
    "SpiralSearch",
    "exponential_rule",
    "minimize",
    "planes",
    "rotate",
    "rotation_matrix",
    "testfunctions",
]
