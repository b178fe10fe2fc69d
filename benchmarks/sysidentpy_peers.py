"""SysIdentPy's FROLS polynomial NARX and neural NARX on the Cascaded Tanks
benchmark: the peer rows beside spiralid's NARX, neural state space and
grey box.

SysIdentPy pins its own NumPy, so this script runs in an environment of
its own and reads the shipped records as CSV files, importing nothing of
spiralid (its figures then cannot move with spiralid's NumPy). The neural
part (``--neural``) also needs PyTorch; its CPU-only build is enough (the
wheel of 2.13.0 is 183 MB, 754 MB installed)::

    python -m venv /tmp/sipy && /tmp/sipy/bin/pip install sysidentpy==0.9.0
    /tmp/sipy/bin/pip install torch  # the CPU-only wheel
    /tmp/sipy/bin/python benchmarks/sysidentpy_peers.py
    /tmp/sipy/bin/python benchmarks/sysidentpy_peers.py --neural

Every degree and lag pair of the grid is fitted on the estimation record
and run free on the test record from its first samples (SysIdentPy's
``predict`` with ``steps_ahead=None``); scored as the benchmark scores (RMS
of the test record's error, the first 5 samples left out, in volts). The
structure a user would keep is chosen without the test record: each
candidate refitted on the estimation record's first two thirds and scored
on its last third. What spiralid's families score on the same test record:
``cascaded_tanks.py`` (grey box), ``cascaded_tanks_narx.py`` and
``cascaded_tanks_nss.py``.

``--neural``: SysIdentPy's ``NARXNN`` configured as its own guide ("Create
a NARX Neural Network") does: degree-1 polynomial regressors (the lagged
signals themselves), two hidden layers of tanh units, mean squared error
by Adam (betas 0.9 and 0.999, eps 1e-5, its default rate 0.01 and batches
of 100), trained one step ahead (series-parallel) and run free (parallel).
The guide trains 2,000 epochs (``--nn-lags 2 --hidden 30 --epochs 2000``
is its network exactly); the grid's default is ``NARXNN``'s own 200, a
tenth of the processor time. The guide's signals are of unit size; here
both are standardised by the estimation record's mean and deviation (the
tanks run 0-10 V, where tanh units start saturated), and the free run is
mapped back to volts. Each lag count and hidden width of the grid is
chosen per seed on the estimation record's last third as above; the seed
(``torch.manual_seed``) draws the network's starting weights. PyTorch runs
on one thread: processor seconds are then one core's. ``--record arm``
runs the same grid on the DaISy robot arm (``daisy_robot_arm.csv``, see
``_splits``) and prints its fit % beside the RMS.
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


def _splits(record: str) -> dict:
    """Where each fit trains and where its free run is scored.

    ``fit`` and ``part`` are the (u, y) the model and the held-back
    candidate train on; ``test`` and ``held`` are the (u, y, skip) their free
    runs cover from the first samples, scored after ``skip``. The tanks: the
    benchmark's two records. The DaISy arm (one record, started in motion):
    estimation on its first two thirds, validation on the last third after
    a free run over the first two as warm-up, as the grey-box page scores
    it; the held-back third is the estimation part's last, warmed up alike.
    """
    if record == "tanks":
        u_est, y_est = _record("cascaded_tanks_est.csv")
        u_test, y_test = _record("cascaded_tanks_val.csv")
        cut = 2 * y_est.size // 3
        return {
            "fit": (u_est, y_est),
            "test": (u_test, y_test, SKIP),
            "part": (u_est[:cut], y_est[:cut]),
            "held": (u_est[cut:], y_est[cut:], SKIP),
        }
    u, y = _record("daisy_robot_arm.csv")
    n_est = 2 * y.size // 3
    cut = 2 * n_est // 3
    return {
        "fit": (u[:n_est], y[:n_est]),
        "test": (u, y, n_est),
        "part": (u[:cut], y[:cut]),
        "held": (u[:n_est], y[:n_est], cut),
    }


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


class _Standardised:
    """A model fitted on standardised signals, predicting in volts."""

    def __init__(self, model, u: np.ndarray, y: np.ndarray) -> None:
        self.model = model
        self.max_lag = model.max_lag
        self.u_shift, self.u_scale = float(u.mean()), float(u.std())
        self.y_shift, self.y_scale = float(y.mean()), float(y.std())
        model.fit(X=self._u(u), y=self._y(y))

    def _u(self, u: np.ndarray) -> np.ndarray:
        return (u - self.u_shift) / self.u_scale

    def _y(self, y: np.ndarray) -> np.ndarray:
        return (y - self.y_shift) / self.y_scale

    def predict(self, X: np.ndarray, y: np.ndarray) -> np.ndarray:
        yhat = self.model.predict(X=self._u(X), y=self._y(y))
        return yhat.astype(float) * self.y_scale + self.y_shift


def _narxnn(lags: int, hidden: int, epochs: int, seed: int):
    import torch
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.neural_network import NARXNN

    torch.manual_seed(seed)
    net = torch.nn.Sequential(
        torch.nn.Linear(2 * lags, hidden),
        torch.nn.Tanh(),
        torch.nn.Linear(hidden, hidden),
        torch.nn.Tanh(),
        torch.nn.Linear(hidden, 1),
    )
    return NARXNN(
        net=net,
        ylag=lags,
        xlag=lags,
        basis_function=Polynomial(degree=1),
        model_type="NARMAX",
        loss_func="mse_loss",
        optimizer="Adam",
        epochs=epochs,
        verbose=False,
        optim_params={"betas": (0.9, 0.999), "eps": 1e-05},
    )


def _free_run_rms(model, u, y, skip: int) -> float:
    """RMS of the free run's error after `skip` samples (the model's first
    ``max_lag`` samples are the measured ones)."""
    with np.errstate(all="ignore"):
        yhat = model.predict(X=u, y=y[: model.max_lag])
    e = (y - yhat)[max(skip, model.max_lag) :].ravel()
    return float(np.sqrt(np.mean(e**2))) if np.all(np.isfinite(e)) else np.inf


def _ints(text: str) -> list[int]:
    """``"0-4"`` or ``"2,3,4"`` as a list of integers."""
    if "-" in text:
        first, last = (int(n) for n in text.split("-"))
        return list(range(first, last + 1))
    return [int(n) for n in text.split(",")]


def neural(
    lags: list[int], hidden: list[int], epochs: int, seeds: list[int], record: str
):
    """The neural NARX's grid per seed, and the test RMS of the lag count
    and width its held-back third keeps."""
    import torch

    torch.set_num_threads(1)  # the machine is shared
    where = _splits(record)
    u_test, y_test, skip = where["test"]
    unit = " V" if record == "tanks" else ""  # the arm's units are unstated
    print(f"seed lags hidden  held-back RMS  test RMS{unit}  s")
    kept, seconds = [], []
    for seed in seeds:
        rows = []
        for n in lags:
            for width in hidden:
                start = time.process_time()
                held = np.nan  # nothing to choose among: no held-back fit
                if len(lags) * len(hidden) > 1:
                    part = _Standardised(
                        _narxnn(n, width, epochs, seed), *where["part"]
                    )
                    held = _free_run_rms(part, *where["held"])
                whole = _Standardised(_narxnn(n, width, epochs, seed), *where["fit"])
                test = _free_run_rms(whole, u_test, y_test, skip)
                seconds.append(time.process_time() - start)
                rows.append((held, test, n, width))
                cells = f"{seed:4d} {n:4d} {width:6d}  {held:13.3f}  {test:12.3f}"
                print(f"{cells}  {seconds[-1]:.1f}", flush=True)
        held, test, n, width = min(rows)
        print(f"seed {seed} keeps lags {n}, {width} units: test {test:.3f}{unit}")
        kept.append(test)
    tests = np.array(kept)
    print(
        f"kept by the held-back third, seeds {seeds[0]}-{seeds[-1]}: test RMS "
        f"median {np.median(tests):.3f}{unit} [{tests.min():.3f}, {tests.max():.3f}]; "
        f"{min(seconds):.0f}-{max(seconds):.0f} processor s per candidate"
    )
    # fit % = 100 (1 - |e| / |y - mean y|) over the scored part
    spread = float(np.std(y_test[skip:]))
    fits = np.sort(100 * (1 - tests / spread))
    print(f"as fit %: median {np.median(fits):.2f} [{fits[0]:.2f}, {fits[-1]:.2f}]")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--degrees", default="1,2,3", help="default 1,2,3")
    parser.add_argument("--lags", default="2,3,4,5", help="default 2,3,4,5")
    parser.add_argument("--terms", type=int, default=15, help="default 15")
    parser.add_argument(
        "--neural", action="store_true", help="the neural NARX instead of FROLS"
    )
    parser.add_argument("--nn-lags", default="2,3,4", help="default 2,3,4")
    parser.add_argument("--hidden", default="10,30", help="default 10,30")
    parser.add_argument("--epochs", type=int, default=200, help="default 200")
    parser.add_argument("--seeds", default="0-4", help="default 0-4")
    parser.add_argument(
        "--record",
        choices=("tanks", "arm"),
        default="tanks",
        help="--neural's record: the Cascaded Tanks or the DaISy robot arm",
    )
    args = parser.parse_args()
    if args.neural:
        hidden = _ints(args.hidden)
        lags = _ints(args.nn_lags)
        neural(lags, hidden, args.epochs, _ints(args.seeds), args.record)
        return
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
