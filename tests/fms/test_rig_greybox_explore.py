"""The growing horizons' exploration against the simulator that made the
record: a stick-slip rig variant (an unknown payload, a breakaway level
above its Coulomb level) whose record's first tenth holds a plain Coulomb
minimum, with a heavier payload and its breakaway level flat below the
Coulomb one, nearly level with the truth's; a polish cannot leave it along
the flat direction, the exploration steps across it to the stiction."""

import numpy as np

from spiralid.fms import FlexibleManipulator, nonlinear_rig, paper_experiment
from spiralid.fms.greybox import RigGreyBox, default_parameter
from spiralid.sysid import IOData, Parameter
from spiralid.sysid.estimation.greybox import fit
from spiralid.sysid.estimation.greybox.parallel import ParallelEvaluator
from spiralid.sysid.estimation.greybox.problem import GreyBoxProblem

FREE = (
    "flexural_rigidity",
    "hub_inertia",
    "payload_mass",
    "damping_ratio",
    "coulomb_friction",
    "static_friction",
)
COULOMB, STATIC = 4, 5  # positions in FREE


def first_tenth():
    """The variant's hub angle over the paper's input, with 1 mrad of noise,
    its first tenth; the fitted structure from the preset's values; the
    truth."""
    rig = nonlinear_rig(payload_mass=0.1, coulomb_friction=0.015, static_friction=0.025)
    rec = paper_experiment().run(rig=FlexibleManipulator(), rng=0).iodata("hub_angle")
    u, ts = np.asarray(rec.u, dtype=float), float(rec.ts)
    made = RigGreyBox(list(FREE), rig, n_modes=2)
    truth = made.initial_values
    noise = 1e-3 * np.random.default_rng(2).standard_normal(u.size)
    y = made.simulate(truth, u, ts) + noise
    k = u.size // 10
    preset = nonlinear_rig()
    params = [
        Parameter(name, 0.05, (0.0, 0.3), "kg")
        if name == "payload_mass"
        else default_parameter(preset, name)
        for name in FREE
    ]
    box = RigGreyBox(params, rig, n_modes=2)
    return GreyBoxProblem(IOData(u[:k], y[:k], ts=ts), box), truth


def test_the_exploration_steps_out_of_a_plain_coulomb_minimum():
    stage, truth = first_tenth()
    coulomb_law = truth * np.where(np.arange(truth.size) == STATIC, 0.5, 1.0)
    with ParallelEvaluator(stage, None) as pool:
        stuck = fit._polish(stage, stage.to_box(coulomb_law), 200, pool)
        explored = fit._explored(stage, stuck, 200, pool)
    before, after = stage.values(stuck), stage.values(explored)
    # The polish stays where the breakaway level is below the Coulomb one
    # (no stiction): that level moves no simulated sample.
    assert before[STATIC] < before[COULOMB]
    np.testing.assert_allclose(before[STATIC], coulomb_law[STATIC], rtol=1e-6)
    # The exploration finds the stiction, at a lower cost of the tenth.
    assert stage(explored) < stage(stuck)
    assert after[STATIC] > after[COULOMB]
    np.testing.assert_allclose(after[STATIC], truth[STATIC], rtol=0.05)
