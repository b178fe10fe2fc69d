"""Parametric system identification, in the order the work flows: records
(`data`, `spectra`) -> model structures (`models`) -> estimation
(`estimation`: the paper's cost, parametrisations, estimators, `identify`)
-> validation (`validation`). Each subpackage imports only from those
before it."""

# --- core (data, arx, cost, identify) ---
from .data import IOData as IOData
from .estimation.core.cost import PaperCost as PaperCost
from .estimation.core.estimators import METHODS as METHODS
from .estimation.core.identify import identify as identify
from .estimation.core.problem import EstimatorResult as EstimatorResult
from .estimation.linear.outputerror import steiglitz_mcbride as steiglitz_mcbride
from .estimation.linear.parametrizations import PARAMETRIZATIONS as PARAMETRIZATIONS
from .estimation.linear.parametrizations import default_bounds as default_bounds
from .estimation.narx.choice import choose_narx as choose_narx
from .estimation.pareto.identify import ParetoIdentification as ParetoIdentification
from .estimation.pareto.identify import identify_pareto as identify_pareto
from .estimation.shared.subspace import subspace_denominator as subspace_denominator
from .estimation.state_space.choice import choose_state_space as choose_state_space
from .models.arx import ARX as ARX
from .models.arx import arx_least_squares as arx_least_squares
from .models.files import load_model as load_model
from .models.fitted import FittedModel as FittedModel
from .models.greybox import GreyBox as GreyBox
from .models.greybox import Parameter as Parameter
from .models.greybox_model import GreyBoxModel as GreyBoxModel
from .models.greybox_model import LinearGreyBoxModel as LinearGreyBoxModel
from .models.identified import IdentifiedModel as IdentifiedModel
from .models.modes import ModeTable as ModeTable
from .models.narx import NARX as NARX
from .models.narx import NARXModel as NARXModel
from .models.narx import PolynomialNARX as PolynomialNARX
from .models.neural_state_space import NeuralStateSpace as NeuralStateSpace
from .models.neural_state_space_model import (
    NeuralStateSpaceModel as NeuralStateSpaceModel,
)
from .models.polynomials import fold_reflection as fold_reflection
from .models.polynomials import format_pole_radius as format_pole_radius
from .models.polynomials import is_stable_polynomial as is_stable_polynomial
from .models.polynomials import max_pole_radius as max_pole_radius
from .models.polynomials import random_stable_polynomial as random_stable_polynomial
from .models.polynomials import step_down as step_down
from .models.polynomials import step_up as step_up
from .models.protocol import FittedModelProtocol as FittedModelProtocol
from .models.shapes import ModeShapes as ModeShapes
from .models.shapes import mac as mac
from .models.shapes import mode_shapes as mode_shapes
from .models.shared import SharedDenominatorModel as SharedDenominatorModel
from .models.shared import SharedModes as SharedModes

# --- validation (validate, plots) ---
# isort: split
from .spectra import find_resonances as find_resonances
from .spectra import modes_from_poles as modes_from_poles
from .spectra import psd as psd
from .validation.correlation import CorrelationTest as CorrelationTest
from .validation.correlation import independence_test as independence_test
from .validation.correlation import whiteness_test as whiteness_test
from .validation.higher_order import BillingsVoon as BillingsVoon
from .validation.higher_order import billings_voon as billings_voon
from .validation.nonlinear import NonlinearChecks as NonlinearChecks
from .validation.outputs import joint_fit as joint_fit
from .validation.selection import choose as choose
from .validation.selection import choose_order as choose_order
from .validation.selection import fits_by_order as fits_by_order
from .validation.selection import knee_point as knee_point
from .validation.selection import validation_fits as validation_fits
from .validation.stabilisation import StabilisationDiagram as StabilisationDiagram
from .validation.stabilisation import stabilisation as stabilisation
from .validation.validate import Realization as Realization
from .validation.validate import Validation as Validation
from .validation.validate import fit_percent as fit_percent
from .validation.validate import realization_tests as realization_tests
from .validation.validate import validate as validate

__all__ = [
    "ARX",
    "METHODS",
    "NARX",
    "PARAMETRIZATIONS",
    "BillingsVoon",
    "CorrelationTest",
    "EstimatorResult",
    "FittedModel",
    "FittedModelProtocol",
    "GreyBox",
    "GreyBoxModel",
    "IOData",
    "IdentifiedModel",
    "LinearGreyBoxModel",
    "ModalParametrization",
    "ModeShapes",
    "ModeTable",
    "NARXModel",
    "NeuralStateSpace",
    "NeuralStateSpaceModel",
    "NonlinearChecks",
    "PaperCost",
    "Parameter",
    "ParetoIdentification",
    "PolynomialNARX",
    "ProjectedCost",
    "Realization",
    "SharedDenominatorModel",
    "SharedModes",
    "StabilisationDiagram",
    "Validation",
    "arx_least_squares",
    "billings_voon",
    "choose",
    "choose_narx",
    "choose_order",
    "choose_state_space",
    "default_bounds",
    "find_resonances",
    "fit_percent",
    "fits_by_order",
    "fold_reflection",
    "format_pole_radius",
    "identify",
    "identify_pareto",
    "independence_test",
    "is_stable_polynomial",
    "joint_fit",
    "knee_point",
    "load_model",
    "mac",
    "max_pole_radius",
    "mode_shapes",
    "modes_from_poles",
    "projected_spiral",
    "psd",
    "random_stable_polynomial",
    "realization_tests",
    "stabilisation",
    "steiglitz_mcbride",
    "step_down",
    "step_up",
    "subspace_denominator",
    "validate",
    "validation_fits",
    "whiteness_test",
]

# The modal search's building blocks, loaded on first use (identify loads
# them itself when a method needs them).
_LAZY = {
    "ModalParametrization": ".estimation.linear.modal",
    "ProjectedCost": ".estimation.linear.varpro",
    "projected_spiral": ".estimation.spiral.projected",
}


def __getattr__(name: str):
    import importlib

    # `plots` needs matplotlib, which is slow to import and not needed to
    # identify or validate a model: load it on first use only.
    if name == "plots":
        return importlib.import_module(".validation.plots", __name__)
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
