"""General-purpose spiral dynamic optimisers (SDA, Eb-SDA, linear adaptive SDA,
Tamura & Yasuda's periodic and convergent settings, the learned-metric
spiral), with optional restarts.

Knows nothing of system identification. See :func:`minimize`;
:func:`differential_evolution` is the baseline beside them.
"""

from spiralid.optim import testfunctions
from spiralid.optim.encoding import AdaptiveEncoding
from spiralid.optim.evolution import differential_evolution
from spiralid.optim.front import knee_point
from spiralid.optim.learned import LearnedMetricSearch, LearnedMetricSpiral
from spiralid.optim.pareto import (
    PARETO_OPTIONS,
    HypervolumeEstimate,
    hypervolume,
    hypervolume_mc,
    minimize_pareto,
    non_dominated,
    thin_front,
)
from spiralid.optim.restarts import Restarts
from spiralid.optim.result import STATUS, OptimiserResult
from spiralid.optim.rotation import planes, rotate, rotation_matrix
from spiralid.optim.rules import (
    ConstantSpiral,
    ConvergentSpiral,
    ExponentialSpiral,
    LinearSpiral,
    PeriodicSpiral,
    SpiralRule,
    StepRateRule,
    descent_rotation,
    exponential_rule,
    rank_condition,
)
from spiralid.optim.spiral import MINIMIZE_OPTIONS, RULES, SpiralSearch, minimize

__all__ = [
    "MINIMIZE_OPTIONS",
    "PARETO_OPTIONS",
    "RULES",
    "STATUS",
    "AdaptiveEncoding",
    "ConstantSpiral",
    "ConvergentSpiral",
    "ExponentialSpiral",
    "HypervolumeEstimate",
    "LearnedMetricSearch",
    "LearnedMetricSpiral",
    "LinearSpiral",
    "OptimiserResult",
    "PeriodicSpiral",
    "Restarts",
    "SpiralRule",
    "SpiralSearch",
    "StepRateRule",
    "descent_rotation",
    "differential_evolution",
    "exponential_rule",
    "hypervolume",
    "hypervolume_mc",
    "knee_point",
    "minimize",
    "minimize_pareto",
    "non_dominated",
    "planes",
    "rank_condition",
    "rotate",
    "rotation_matrix",
    "testfunctions",
    "thin_front",
]
