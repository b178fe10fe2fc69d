"""The names a user chooses among, in one module that imports nothing heavy.

``spiralid --help`` builds every parser from these names without loading
SciPy, Numba or matplotlib (tests/test_import_time.py checks it). Each table
that maps a name to its implementation (:data:`spiralid.optim.RULES`,
:data:`spiralid.sysid.METHODS`, :data:`spiralid.sysid.PARAMETRIZATIONS`,
:data:`spiralid.optim.pareto.PARETO_METHODS`) is keyed by these and checks at
import, with :func:`require_names`, that it holds exactly them.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = [
    "DEFAULT_METHOD",
    "DEFAULT_PARETO_METHOD",
    "METHOD_NAMES",
    "OBJECTIVES",
    "PARAMETRIZATION_NAMES",
    "PARETO_METHOD_NAMES",
    "RIG_PARAMETERS",
    "RULE_NAMES",
    "require_names",
]

# The spiral rules of spiralid.optim.minimize, in the order tables list them.
RULE_NAMES = (
    "sda",
    "ebsda",
    "lasda",
    "ebsda-scaled",
    "periodic",
    "convergent",
    "learned-metric",
)
# The rules a multi-objective search can drive: those that set each point's
# radius and angle, and the learned-metric poll; not the step-rate rules
# (periodic, convergent), whose step schedule belongs to a single centre.
PARETO_METHOD_NAMES = ("sda", "ebsda", "lasda", "ebsda-scaled", "learned-metric")
# The default rule of minimize_pareto, identify_pareto and `spiralid pareto`:
# the learned-metric poll, the best of these rules on the benchmark problems
# (docs/results/multiobjective.md). The paper's rule, Eb-SDA, stays
# available by name ("ebsda"); what reproduces the paper names it.
DEFAULT_PARETO_METHOD = "learned-metric"
# Identification methods: every rule, then the baselines and the default.
METHOD_NAMES = (*RULE_NAMES, "de", "spiral", "ls", "oe")
DEFAULT_METHOD = "spiral"
PARAMETRIZATION_NAMES = ("coefficients", "reflection", "modal")
# Every Pareto objective by name, with its axis label.
OBJECTIVES: dict[str, str] = {
    "cost": "simulation cost, eq. (2) (% of rms(y))",
    "frequency": "frequency-response error (dB, coherence-weighted RMS)",
    "one-step": "one-step cost, eq. (2) (% of rms(y))",
    "order": "parameters na + nb",
}

# The fields of the flexible manipulator a rig grey box can free
# (spiralid.fms.greybox.RigGreyBox, `spiralid identify --model rig --free`),
# with their units: the dataclass's physical fields and two of its
# properties, flexural_rigidity (E I, set through the Young's modulus) and
# mass_per_length (rho A, set through the density), the two numbers the
# finite elements read from the beam's material and cross-section.
RIG_PARAMETERS: dict[str, str] = {
    "length": "m",
    "width": "m",
    "thickness": "m",
    "youngs_modulus": "Pa",
    "density": "kg/m^3",
    "flexural_rigidity": "N m^2",
    "mass_per_length": "kg/m",
    "hub_inertia": "kg m^2",
    "payload_mass": "kg",
    "payload_inertia": "kg m^2",
    "damping_ratio": "",
    "mass_damping": "1/s",
    "stiffness_damping": "s",
    "hub_friction": "N m s/rad",
    "coulomb_friction": "N m",
    "static_friction": "N m",
    "stribeck_velocity": "rad/s",
    "torque_limit": "N m",
    # Not a field: the record's input delay before the rig (a real arm's).
    "input_delay": "s",
}


def require_names(table: Iterable[str], names: tuple[str, ...], what: str) -> None:
    """Raise if `table`'s names are not exactly `names`, in that order.

    Called where a table is built, so that a name added to one place and not
    the other fails at import, not in a user's run.
    """
    found = tuple(table)
    if found != names:
        raise RuntimeError(
            f"{what} holds {found}, but spiralid.choices lists {names}: "
            "update both together"
        )
