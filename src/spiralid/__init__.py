"""spiralid: system identification with spiral dynamic optimisation.

Implements the Spiral Dynamic Algorithm (SDA, Tamura & Yasuda 2011) and the
exponential-based SDA (Eb-SDA) of Nasir, Ismail, Ahmad and Tokhi,
"Exponential-based spiral dynamic algorithm for modelling of a flexible
manipulator system", and applies them to ARX modelling of a flexible
manipulator.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("spiralid")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+unknown"

# --- optim ---
from . import optim as optim
from .optim import SpiralResult as SpiralResult
from .optim import minimize as minimize

# isort: split
# --- fms ---
from . import fms as fms
from .fms import FlexibleManipulator as FlexibleManipulator
from .fms import Recording as Recording

# --- sysid ---
from .sysid import ARX as ARX
from .sysid import IdentifiedModel as IdentifiedModel
from .sysid import IOData as IOData
from .sysid import PaperCost as PaperCost
from .sysid import Validation as Validation
from .sysid import arx_least_squares as arx_least_squares
from .sysid import identify as identify
from .sysid import validate as validate

# isort: split
# --- example data ---
from . import datasets as datasets

# --- report ---
