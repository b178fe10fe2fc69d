"""`import spiralid` is cheap: SciPy, Numba and matplotlib load on first use."""

import statistics
import subprocess
import sys


def _fresh(code: str) -> str:
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    return proc.stdout.strip()


def _import_seconds(module: str) -> float:
    code = (
        "import time; t = time.perf_counter(); "
        f"import {module}; print(time.perf_counter() - t)"
    )
    return statistics.median(float(_fresh(code)) for _ in range(3))


def test_import_loads_no_heavy_dependency():
    loaded = _fresh(
        "import sys, spiralid; "
        "print(sorted(m for m in ('scipy', 'numba', 'matplotlib', 'numpy') "
        "if m in sys.modules))"
    )
    assert loaded == "[]"


def test_import_is_cheaper_than_numpy():
    # A ratio in fresh interpreters, not a fixed time: the machine's speed and
    # load cancel. NumPy itself is the yardstick of a light import.
    assert _import_seconds("spiralid") < _import_seconds("numpy")


def test_public_names_still_resolve():
    import spiralid

    assert spiralid.IOData is spiralid.sysid.IOData
    assert spiralid.minimize is spiralid.optim.minimize
    # Documented at the top level (README, "Which method to use").
    assert spiralid.steiglitz_mcbride is spiralid.sysid.steiglitz_mcbride
    assert {"identify", "datasets", "fms"} <= set(dir(spiralid))
