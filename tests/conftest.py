"""Test-wide settings.

Hypothesis draws its examples from a fixed seed (``derandomize``), so a run
on CI explores exactly the examples a run here did: a property test cannot
pass here and fail there by luck.

One BLAS thread, as the ``spiralid`` command runs (see
``spiralid.cli.console``): the suite's problems are small and a threaded
BLAS makes them several times slower on a loaded machine. Set before NumPy
is first imported; a setting of the caller's own is kept.
"""

import os

for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

from hypothesis import settings  # noqa: E402

settings.register_profile("spiralid", derandomize=True, deadline=None)
settings.load_profile("spiralid")
