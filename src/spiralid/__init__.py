"""spiralid: system identification with spiral dynamic optimisation.

Implements the Spiral Dynamic Algorithm (SDA, Tamura & Yasuda 2011) and the
exponential-based SDA (Eb-SDA) of Nasir, Ismail, Ahmad and Tokhi,
"Exponential-based spiral dynamic algorithm for modelling of a flexible
manipulator system", and applies them to ARX modelling of a flexible
manipulator.
"""

# The public names load on first use (PEP 562): `import spiralid` stays as
# cheap as the metadata lookup above, and SciPy, Numba and the compiled
# kernels are imported only by the parts that need them.
_SUBPACKAGES = ("datasets", "fms", "optim", "report", "reproduction", "sysid")
_NAMES = {
    "OptimiserResult": "optim",
    "minimize": "optim",
    "FlexibleManipulator": "fms",
    "Recording": "fms",
    "ARX": "sysid",
    "NARX": "sysid",
    "NARXModel": "sysid",
    "PolynomialNARX": "sysid",
    "billings_voon": "sysid",
    "IdentifiedModel": "sysid",
    "IOData": "sysid",
    "PaperCost": "sysid",
    "Validation": "sysid",
    "arx_least_squares": "sysid",
    "steiglitz_mcbride": "sysid",
    "identify": "sysid",
    "identify_pareto": "sysid",
    "choose": "sysid",
    "choose_order": "sysid",
    "validate": "sysid",
    "SharedDenominatorModel": "sysid",
}
__all__ = ["__version__", *_SUBPACKAGES, *_NAMES]


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("spiralid")
    except PackageNotFoundError:  # running from a source tree without install
        return "0.0.0+unknown"


def __getattr__(name: str):
    import importlib

    if name == "__version__":
        # Looked up on first use: the metadata scan costs more than the rest
        # of `import spiralid`, which the command's Ctrl-C handling waits on.
        globals()[name] = value = _version()
        return value
    if name in _SUBPACKAGES:
        return importlib.import_module(f".{name}", __name__)
    if name in _NAMES:
        value = getattr(importlib.import_module(f".{_NAMES[name]}", __name__), name)
        globals()[name] = value  # later look-ups skip this function
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
