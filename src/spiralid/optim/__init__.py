"""General-purpose spiral dynamic optimisers (SDA, Eb-SDA, linear adaptive SDA).

Knows nothing of system identification. See :func:`minimize`;
:func:`differential_evolution` is the baseline beside them.
"""

from spiralid.optim import testfunctions
from spiralid.optim.evolution import differential_evolution
from spiralid.optim.rotation import planes, rotate, rotation_matrix
from spiralid.optim.rules import (
    ConstantSpiral,
    ExponentialSpiral,
    LinearSpiral,
    SpiralRule,
    exponential_rule,
)
from spiralid.optim.spiral import RULES, SpiralResult, SpiralSearch, minimize

__all__ = [
    "RULES",
    "ConstantSpiral",
    "ExponentialSpiral",
    "LinearSpiral",
    "SpiralResult",
    "SpiralRule",
    "SpiralSearch",
    "differential_evolution",
    "exponential_rule",
    "minimize",
    "planes",
    "rotate",
    "rotation_matrix",
    "testfunctions",
]
