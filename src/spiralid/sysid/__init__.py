"""Parametric system identification: data, ARX structures, the paper's cost,
estimation and validation."""

# --- core (data, arx, cost, identify) ---
from .arx import ARX as ARX
from .arx import arx_least_squares as arx_least_squares
from .cost import PaperCost as PaperCost
from .data import IOData as IOData
from .estimators import METHODS as METHODS
from .estimators import EstimatorResult as EstimatorResult
from .identify import identify as identify
from .model import IdentifiedModel as IdentifiedModel
from .outputerror import steiglitz_mcbride as steiglitz_mcbride
from .parametrizations import PARAMETRIZATIONS as PARAMETRIZATIONS
from .parametrizations import default_bounds as default_bounds
from .polynomials import fold_reflection as fold_reflection
from .polynomials import format_pole_radius as format_pole_radius
from .polynomials import is_stable_polynomial as is_stable_polynomial
from .polynomials import max_pole_radius as max_pole_radius
from .polynomials import random_stable_polynomial as random_stable_polynomial
from .polynomials import step_down as step_down
from .polynomials import step_up as step_up

# --- validation (validate, plots) ---
# isort: split
from .correlation import CorrelationTest as CorrelationTest
from .correlation import independence_test as independence_test
from .correlation import whiteness_test as whiteness_test
from .spectra import find_resonances as find_resonances
from .spectra import modes_from_poles as modes_from_poles
from .spectra import psd as psd
from .validate import Realization as Realization
from .validate import Validation as Validation
from .validate import fit_percent as fit_percent
from .validate import realization_tests as realization_tests
from .validate import validate as validate


def __getattr__(name: str):
    # `plots` needs matplotlib, which is slow to import and not needed to
    # identify or validate a model: load it on first use only.
    if name == "plots":
        import importlib

        return importlib.import_module(".plots", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
