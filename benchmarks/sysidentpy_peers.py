"""SysIdentPy's FROLS polynomial NARX on the Cascaded Tanks benchmark: the
peer row beside spiralid's NARX, neural state space and grey box.

SysIdentPy pins its own NumPy, so this script runs in an environment of
its own and reads the shipped records as CSV files, importing nothing of
spiralid (its figures then cannot move with spiralid's NumPy)::

    python -m venv /tmp/sipy && /tmp/sipy/bin/pip install sysidentpy
    /tmp/sipy/bin/python benchmarks/sysidentpy_peers.py

Every degree and lag pair of the grid is fitted on the estimation record
and run free on the test record from its first samples (SysIdentPy's
``predict`` with ``steps_ahead=None``); scored as the benchmark scores (RMS
of the test record's error, the first 5 samples left out, in volts). The
structure a user would keep is chosen without the test record: each
candidate refitted on the estimation record's first two thirds and scored
on its last third. What spiralid's families score on the same test record:
``cascaded_tanks.py`` (grey box), ``cascaded_tanks_narx.py`` and
``cascaded_tanks_nss.py``.
"""

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

RECORDS = Path(__file__).resolve().parents[1] / "src" / "spiralid" / "datasets"
SKIP = 5  # the benchmark's: the first samples may set the state


def _record(name: str) -> tuple[np.ndarray, np.ndarray]:
    data = np.loadtxt(RECORDS / name, delimiter=",", skiprows=1)
    return data[:, :1], data[:, 1:2]


def _frols(degree: int, lags: int, n_terms: int):
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.model_structure_selection import FROLS
    from sysidentpy.parameter_estimation import LeastSquares

    return FROLS(
        order_selection=True,
        n_info_values=n_terms,
        info_criteria="aic",
        ylag=lags,
        xlag=lags,
        estimator=LeastSquares(),
        basis_function=Polynomial(degree=degree),
    )


def _free_run_rms(model, u, y, skip: int) -> float:
    """RMS of the free run's error after `skip` samples (the model's first
    ``max_lag`` samples are the measured ones)."""
    with np.errstate(all="ignore"):
        yhat = model.predict(X=u, y=y[: model.max_lag])
    e = (y - yhat)[max(skip, model.max_lag) :].ravel()
    return float(np.sqrt(np.mean(e**2))) if np.all(np.isfinite(e)) else np.inf


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--degrees", default="1,2,3", help="default 1,2,3")
    parser.add_argument("--lags", default="2,3,4,5", help="default 2,3,4,5")
    parser.add_argument("--terms", type=int, default=15, help="default 15")
    args = parser.parse_args()
    # FROLS caps n_info_values at the candidate count and says so each time.
    warnings.filterwarnings("ignore", message="n_info_values is greater")
    u_est, y_est = _record("cascaded_tanks_est.csv")
    u_test, y_test = _record("cascaded_tanks_val.csv")
    cut = 2 * y_est.size // 3
    print("degree lags terms  held-back RMS  test RMS (V)  s")
    rows = []
    for degree in (int(d) for d in args.degrees.split(",")):
        for lags in (int(n) for n in args.lags.split(",")):
            start = time.process_time()
            part = _frols(degree, lags, args.terms)
            part.fit(X=u_est[:cut], y=y_est[:cut])
            held = _free_run_rms(part, u_est[cut:], y_est[cut:], SKIP)
            whole = _frols(degree, lags, args.terms)
            whole.fit(X=u_est, y=y_est)
            test = _free_run_rms(whole, u_test, y_test, SKIP)
            seconds = time.process_time() - start
            rows.append((held, test, degree, lags))
            n = len(whole.final_model)
            cells = f"{degree:6d} {lags:4d} {n:5d}  {held:13.3f}  {test:12.3f}"
            print(f"{cells}  {seconds:.1f}")
    finite = [r for r in rows if np.isfinite(r[1])]
    held, test, degree, lags = min(rows)
    print(
        f"kept by the held-back third: degree {degree}, lags {lags}: test {test:.3f} V"
    )
    if finite:
        tests = [r[1] for r in finite]
        print(f"test RMS over the grid: {min(tests):.3f}-{max(tests):.3f} V")
    diverged = sum(not np.isfinite(r[0]) for r in rows)
    print(f"free runs leaving the float range: {diverged} of {len(rows)} held-back")


if __name__ == "__main__":
    main()
