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
# --- fms ---
# --- sysid ---
# --- report ---
