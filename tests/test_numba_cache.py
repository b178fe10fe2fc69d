"""Every compiled kernel is cached on disk, and a second process loads it.

The first `spiralid reproduce` after an install pays Numba's compilation
once; these tests keep it once. They count the dispatchers' cache hits and
misses, never wall time.
"""

import importlib
import json
import os
import re
import subprocess
import sys
from pathlib import Path

from numba.core.caching import NullCache
from numba.core.dispatcher import Dispatcher

SRC = Path(__file__).resolve().parents[1] / "src" / "spiralid"


def _kernel_modules() -> list[str]:
    """Every module of the package that compiles with Numba."""
    found = []
    for path in sorted(SRC.rglob("*.py")):
        if re.search(r"@numba\.(njit|jit)\b", path.read_text()):
            parts = path.relative_to(SRC.parent).with_suffix("").parts
            found.append(".".join(parts))
    return found


# Kernels compiled for a caller's own functions: a cached copy would name
# the caller's module, which the next process may not import.
NOT_CACHED = {"spiralid.sysid.models.greybox_run.rk4_compiled"}


def test_every_kernel_is_cached_on_disk():
    modules = _kernel_modules()
    assert "spiralid.optim._kernels" in modules
    uncached = []
    for name in modules:
        for attr, value in vars(importlib.import_module(name)).items():
            # A dispatcher without cache=True holds a NullCache.
            if isinstance(value, Dispatcher) and isinstance(value._cache, NullCache):
                uncached.append(f"{name}.{attr}")
    assert sorted(uncached) == sorted(NOT_CACHED)


_CALL = """
import json, numpy as np
from spiralid.optim import _kernels
_kernels.deviations(np.linspace(0.0, 1.0, 5))
_kernels.promote(np.ones((3, 2)), np.zeros(3))
stats = [_kernels.deviations.stats, _kernels.promote.stats]
print(json.dumps([sum(s.cache_hits.values()) for s in stats]
                 + [sum(s.cache_misses.values()) for s in stats]))
"""


def _hits_and_misses(cache_dir: Path) -> list[int]:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache_dir)}
    out = subprocess.run(
        [sys.executable, "-c", _CALL], env=env, capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def test_a_second_process_loads_the_kernels_instead_of_compiling(tmp_path):
    # NUMBA_CACHE_DIR is where an installed package's cache goes when its
    # own directory is read-only (else the user's cache directory).
    assert _hits_and_misses(tmp_path) == [0, 0, 1, 1]  # compiled and saved
    assert any(tmp_path.rglob("*.nbi"))
    assert _hits_and_misses(tmp_path) == [1, 1, 0, 0]  # loaded, not compiled
