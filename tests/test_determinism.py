"""The same seed gives the same numbers, bit for bit, whatever the thread
settings of BLAS, OpenMP and Numba, and with other runs loading the machine
(one or several worker processes: tests/report/test_experiment.py).

Each run is a fresh interpreter (thread counts are read when the libraries
load); they run at the same time, so each is also timed under load.
"""

import os
import subprocess
import sys

from patience import allowance

SCRIPT = """
import hashlib
import spiralid as sid

data = sid.datasets.robot_arm()
est, val = data.split(2 / 3)
digest = hashlib.sha256()
for seed in (0, 1):
    model = sid.identify(
        est, sid.ARX(8, 8, 0), method="ebsda", refine=True, rng=seed,
        max_nfev=1500, initial="measured",
    )
    fit = sid.validate(model, val, warmup=est).fit_percent
    digest.update(model.theta.tobytes() + float(fit).hex().encode())
model = sid.identify(est, sid.ARX(8, 8, 0), method="oe", initial="measured")
digest.update(model.theta.tobytes())
print(digest.hexdigest())
"""

THREAD_VARIABLES = (
    "OPENBLAS_NUM_THREADS",
    "OMP_NUM_THREADS",
    "MKL_NUM_THREADS",
    "NUMBA_NUM_THREADS",
)


def _env(threads: int | None) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in THREAD_VARIABLES}
    if threads is not None:
        env |= dict.fromkeys(THREAD_VARIABLES, str(threads))
    return env


def test_same_seed_same_bits_under_any_thread_setting():
    settings = [1, 2, 4, None]
    hang = allowance(600)  # a safety net only, see patience.py
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", SCRIPT],
            env=_env(t),
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for t in settings
    ]
    digests = {}
    for t, proc in zip(settings, procs, strict=True):
        out, err = proc.communicate(timeout=hang)
        assert proc.returncode == 0, err
        digests[t] = out.strip()
    assert len(set(digests.values())) == 1, digests
