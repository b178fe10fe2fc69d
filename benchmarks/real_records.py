"""The default NARX on real nonlinear records that are not in the repository.

For each record found in ``--data DIR`` it prints the free-run validation
fit % (``100 (1 - |y - yhat| / |y - mean y|)``) and the seconds of:

- ``ARX``: the default method's ARX (``identify(est, ARX(n, n, nk),
  integrator=k)``); the order ``n`` (and ``k`` where the record allows an
  integrator) is chosen on the estimation part only: each candidate is fitted
  on its first 4/5 and :func:`spiralid.sysid.choose_order` (tolerance 1 point)
  picks by the free-run fit on its last 1/5; the chosen one is refitted on the
  whole estimation part. The validation part is never looked at.
- ``NARX``: the default NARX, ``identify(est, NARX(n', n, nk,
  integrator=k))`` with the chosen lags (``n' = n - 1`` with an integrator:
  the NARX then holds ``ARX(n, n, nk)``, docs/guide/models.md), default
  method, hidden units and hold-out.
- ``poly FROLS``: :class:`spiralid.sysid.PolynomialNARX` ``(n, n, nk,
  degree=2, n_terms=15)`` (default method: FROLS).
- ``SysIdentPy FROLS`` (if ``sysidentpy`` imports): its FROLS with the same
  lags, degree 2, 15 terms, least squares, as benchmarks/nonparametric.py.
- ``SysIdentPy neural NARX`` (if ``sysidentpy`` and ``torch`` import): its
  NARXNN, one hidden layer of 10 tanh units, Adam, 200 epochs of one-step
  training on the scaled signals, the same lags, run free.

Diagnostics (``--methods``): ``narx-holdout0``, the default NARX with
nothing held back (``holdout=0``: up to 50 rounds on the whole estimation
part); ``narx-fair``, :func:`fair_stopping`. The NARX rows run for every
seed of ``--seeds`` (the ARX and the order choice use seed 0; FROLS is not
random) and say whether training kept the linear start or how many final
Levenberg-Marquardt rounds it ran.

SysIdentPy pins ``numpy<=2.3.5``: run its rows from a separate virtual
environment holding spiralid and sysidentpy (``--methods sipy,sipy-nn``,
``--lags`` to reuse the lags the main run chose).

Every record is detrended by its estimation part's means (the same shift for
the validation part) and every model runs free from rest. A record with one
experiment is validated on the part after the estimation part, its free run
starting at the record's start (the estimation part is the warm-up); a
record with a separate validation experiment runs that experiment free from
rest.

Records (files looked for in ``DIR``; a missing file skips its record):

``cascaded tanks`` -- ``dataBenchmark.csv``, columns ``uEst, uVal, yEst,
    yVal, Ts`` (1024 samples each, Ts = 4 s): the Cascaded Tanks benchmark
    (M. Schoukens, P. Mattsson, T. Wigren, J.-P. Noel, 2016,
    nonlinearbenchmark.org). Estimation ``uEst, yEst``, validation ``uVal,
    yVal`` (the benchmark's split). A copy is in the history of
    github.com/forgi86/dynonet (MIT), ``examples/CTS/data/dataBenchmark.csv``
    at commit 0bdf706.
``silverbox`` -- ``SNLS80mV.csv``, columns ``V1`` (input), ``V2`` (output),
    131,072 samples at 610.35 Hz (T. Wigren, J. Schoukens, Uppsala report
    2013-006, nonlinearbenchmark.org). Validation: the first 40,000 samples
    (the "arrow", Gaussian noise of growing amplitude, the benchmark's test
    part); estimation: ``--silverbox-est`` samples (default 17,384: two of the
    ten multisine realisations with their transients) from sample 40,700 on.
    A copy: github.com/antonior92/sysid-neuralnet (MIT),
    ``data/SilverboxFiles/SNLS80mV.csv``.
``drives 0.5`` / ``drives 1.0`` / ``drives 1.5`` -- ``drive.mat`` with
    ``u1, z1`` (PRBS amplitude 1.0), ``u2, z2`` (1.5), ``u3, z3`` (0.5),
    500 samples each, Ts = 20 ms: the coupled electric drives (T. Wigren,
    M. Schoukens, Uppsala report 2017-024, whose DATAPRBS.csv holds the
    same kind of records; this copy was not compared with it), the speed
    measured by a pulse counter blind to the sign. Estimation on
    the first 300 samples, validation on the last 200 (the benchmark's
    split). A copy: github.com/zhenwendai/RGP (BSD-3),
    ``datasets/system_identification/drive.mat``.
``ball and beam`` -- ``ballbeam.dat``, two columns (beam angle, ball
    position), 1000 samples, Ts = 0.1 s: DaISy 96-004 (KU Leuven ESAT-SISTA),
    2/3 - 1/3; an integrator (1 or 2) is a candidate of the order choice.
    Copy: the same RGP folder.
``hair dryer`` -- ``dryer.dat``, two columns (voltage, outlet temperature),
    1000 samples, Ts = 0.08 s: DaISy 96-006, 2/3 - 1/3; close to linear.
    Copy: the same RGP folder.
``hydraulic actuator`` -- ``actuator.mat`` with ``u`` (valve opening) and
    ``p`` (oil pressure), 1024 samples: the hydraulic crane of J. Sjoberg et
    al., Automatica 31(12), 1995, estimation on the first 512 samples and
    validation on the last 512 (their split). Copy: the same RGP folder.

Usage: ``python benchmarks/real_records.py --data DIR [--records a,b]
[--methods arx,narx,poly,sipy,sipy-nn] [--orders 1,2,3,4,6] [--seeds 0-4]
[--lags "record=n,k;..."]`` (minutes per record at most, one process).
"""

from __future__ import annotations

import argparse
import os
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
from _cli import seed_list

from spiralid.sysid import (
    ARX,
    NARX,
    IOData,
    PolynomialNARX,
    choose_order,
    fit_percent,
    identify,
)


@dataclass
class Record:
    """An estimation part, a validation part and how to run it."""

    name: str
    est: IOData
    val: IOData
    joined: bool  # the validation part follows the estimation part
    integrators: tuple[int, ...] = (0,)
    nk: int = 1


def _csv(path: Path) -> dict[str, np.ndarray]:
    """Columns of a CSV file with a header (trailing commas allowed)."""
    raw = np.genfromtxt(path, delimiter=",", names=True, dtype=float)
    return {n: raw[n] for n in raw.dtype.names if not np.all(np.isnan(raw[n]))}


def _pair(u, y, ts, n_est: int) -> tuple[IOData, IOData]:
    d = IOData(np.asarray(u, float).ravel(), np.asarray(y, float).ravel(), ts=ts)
    return IOData(d.u[:n_est], d.y[:n_est], ts=ts), IOData(
        d.u[n_est:], d.y[n_est:], ts=ts
    )


def load_records(folder: Path, silverbox_est: int) -> list[Record]:
    """Every record whose file is in `folder` (see the module docstring)."""
    from scipy.io import loadmat

    out = []
    f = folder / "dataBenchmark.csv"
    if f.exists():
        c = _csv(f)
        ts = float(c["Ts"][0]) if "Ts" in c else 4.0
        est = IOData(c["uEst"], c["yEst"], ts=ts)
        val = IOData(c["uVal"], c["yVal"], ts=ts)
        out.append(Record("cascaded tanks", est, val, joined=False))
    f = folder / "SNLS80mV.csv"
    if f.exists():
        c = _csv(f)
        ts = 1 / 610.35
        u, y = c["V1"], c["V2"]
        est = IOData(
            u[40700 : 40700 + silverbox_est], y[40700 : 40700 + silverbox_est], ts=ts
        )
        val = IOData(u[:40000], y[:40000], ts=ts)
        out.append(Record("silverbox", est, val, joined=False))
    f = folder / "drive.mat"
    if f.exists():
        m = loadmat(f)
        for i in (3, 1, 2):
            amp = float(np.max(np.abs(m[f"u{i}"])))
            est, val = _pair(m[f"u{i}"], m[f"z{i}"], 0.02, 300)
            out.append(Record(f"drives {amp:.1f}", est, val, joined=True))
    f = folder / "ballbeam.dat"
    if f.exists():
        d = np.loadtxt(f)
        est, val = IOData(d[:, 0], d[:, 1], ts=0.1).split(2 / 3)
        out.append(Record("ball and beam", est, val, True, integrators=(0, 1, 2)))
    f = folder / "dryer.dat"
    if f.exists():
        d = np.loadtxt(f)
        est, val = IOData(d[:, 0], d[:, 1], ts=0.08).split(2 / 3)
        out.append(Record("hair dryer", est, val, joined=True))
    f = folder / "actuator.mat"
    if f.exists():
        m = loadmat(f)
        est, val = _pair(m["u"], m["p"], 1.0, 512)
        out.append(Record("hydraulic actuator", est, val, joined=True))
    return out


def detrended(rec: Record) -> tuple[IOData, IOData]:
    """Both parts shifted by the estimation part's means."""
    return rec.est.detrend(), rec.val.detrend(like=rec.est)


def free_run(model_sim, est: IOData, val: IOData, joined: bool) -> np.ndarray:
    """The validation part of the free run from rest."""
    if joined:
        return model_sim(np.r_[est.u, val.u])[est.n :]
    return model_sim(val.u)


def choose_arx(est: IOData, rec: Record, orders, seed: int):
    """Order (and integrators) by free-run fit on the estimation part's
    last fifth, each candidate fitted on its first four fifths."""
    fit_part, held = est.split(4 / 5)
    cands, models = [], []
    for k in rec.integrators:
        for n in orders:
            if k and n < k:
                continue
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                m = identify(fit_part, ARX(n, n, rec.nk), integrator=k, rng=seed)
            cands.append((n, k))
            models.append(m)
    idx = choose_order(models, held, warmup=fit_part, tolerance=1.0)
    return cands[idx]


def _sipy_frols(est, val, joined, n, nk, k):
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.model_structure_selection import FROLS
    from sysidentpy.parameter_estimation import LeastSquares

    def tr(y):
        for _ in range(k):
            y = np.diff(y, prepend=0.0)
        return y

    model = FROLS(
        ylag=n - 1 if k else n,
        xlag=n,
        order_selection=False,
        n_terms=15,
        estimator=LeastSquares(),
        basis_function=Polynomial(degree=2),
        model_type="NARMAX",
    )
    model.fit(X=est.u[:, None], y=tr(est.y)[:, None])
    u = np.r_[est.u, val.u] if joined else val.u
    pad = max(n, n + nk)
    yf = model.predict(
        X=np.r_[np.zeros(pad), u][:, None], y=np.zeros((pad, 1)), steps_ahead=None
    )[pad:, 0]
    for _ in range(k):
        yf = np.cumsum(yf)
    return yf[est.n :] if joined else yf


def _sipy_nn(est, val, joined, n, nk, k, seed):
    import torch
    from sysidentpy.basis_function import Polynomial
    from sysidentpy.neural_network import NARXNN

    torch.manual_seed(seed)
    ny = n - 1 if k else n
    nu = n

    class Net(torch.nn.Module):
        def __init__(self):
            super().__init__()
            self.lin = torch.nn.Linear(ny + nu, 10)
            self.out = torch.nn.Linear(10, 1)

        def forward(self, x):
            return self.out(torch.tanh(self.lin(x)))

    yt = est.y
    for _ in range(k):
        yt = np.diff(yt, prepend=0.0)
    sy = float(np.std(yt)) or 1.0
    su = float(np.std(est.u)) or 1.0
    model = NARXNN(
        net=Net(), ylag=ny, xlag=nu, loss_func="mse_loss", optimizer="Adam",
        epochs=200, verbose=False, learning_rate=3e-3,
        basis_function=Polynomial(degree=1),
    )  # fmt: skip
    model.fit(X=(est.u / su)[:, None], y=(yt / sy)[:, None])
    u = np.r_[est.u, val.u] if joined else val.u
    pad = max(ny, nu)
    yf = model.predict(X=np.r_[np.zeros(pad), u / su][:, None], y=np.zeros((pad, 1)))
    yf = yf[pad:, 0] * sy
    for _ in range(k):
        yf = np.cumsum(yf)
    return yf[est.n :] if joined else yf


def fair_stopping(est: IOData, st: NARX, seed: int):
    """Diagnostic: the early stopping of ``identify(est, st, method="oe")``
    with a linear start fitted on the training part only.

    The default NARX's linear start is fitted on the whole estimation part,
    the held-back fifth included, so on that fifth it is scored in-sample
    while the network's rounds are scored out of sample. Here the start is
    the default ARX of the first four fifths; the round count with the
    lowest held-back cost is then run from the usual start on the whole
    part (``holdout=0``). Uses private training code (``narx_starts._with_hidden``,
    ``NARXProblem.polish``); ``st`` without integrator.
    """
    from spiralid.sysid.estimation.narx.problem import NARXProblem
    from spiralid.sysid.estimation.narx.starts import _with_hidden

    prob = NARXProblem(est, st, "simulation", "rest", 0.2, np.random.default_rng(seed))
    prob.decay = 1e-3
    part = IOData(est.u[: prob.split], est.y[: prob.split], ts=est.ts)
    theta = np.asarray(identify(part, ARX(st.ny, st.nu, st.nk), rng=seed).theta)
    start = _with_hidden(
        prob, st.from_arx(theta[: st.ny], theta[st.ny :], prob.scaling)
    )
    _, rounds = prob.polish(start, "simulation", 50, 3)
    if rounds == 0:
        # The start itself: the whole part's linear model, which the NARX holds.
        return identify(est, ARX(st.ny, st.nu, st.nk), rng=seed), 0
    opts = {"holdout": 0.0, "max_rounds": rounds, "patience": rounds + 1}
    return identify(est, st, method="oe", rng=seed, **opts), rounds


def run(rec: Record, methods, orders, seeds, lags=None) -> None:
    est, val = detrended(rec)
    t0 = time.perf_counter()
    n, k = lags if lags else choose_arx(est, rec, orders, 0)
    t_choice = time.perf_counter() - t0
    nk = rec.nk
    print(
        f"\n## {rec.name}: {est.n} estimation, {val.n} validation samples; "
        f"chosen ARX({n}, {n}, {nk}), integrator={k} "
        f"({'given' if lags else f'{t_choice:.1f} s of order choice'})",
        flush=True,
    )
    print("| model | seed | validation fit % | s | note |", flush=True)
    print("|---|---|---|---|---|", flush=True)

    def row(label, seed, fn):
        t = time.perf_counter()
        note = ""
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                yhat = fn()
            if isinstance(yhat, tuple):
                yhat, note = yhat
            ok = np.all(np.isfinite(yhat))
            fit = fit_percent(val.y, yhat) if ok else -np.inf
            fit = f"{fit:.2f}" if fit > -999 else "diverges"
        except ImportError:
            return
        except Exception as exc:  # a failing model is reported, not hidden
            fit = f"fails: {type(exc).__name__}: {str(exc)[:80]}"
        wall = time.perf_counter() - t
        print(f"| {label} | {seed} | {fit} | {wall:.1f} | {note} |", flush=True)

    def sim(model):
        return free_run(model.simulate, est, val, rec.joined)

    def narx_note(model):
        r = model.result
        if r.get("kept_linear"):
            return "kept the linear start"
        rounds = r.get("final_rounds", r.get("nit"))
        return f"start {r.get('start')}, {rounds} final rounds"

    if "arx" in methods:
        row(
            f"ARX({n}, {n}, {nk}), integrator={k}, default method",
            0,
            lambda: sim(identify(est, ARX(n, n, nk), integrator=k, rng=0)),
        )
    ny = n - 1 if k else n
    st = NARX(ny, n, nk, integrator=k)
    for seed in seeds:
        if "narx" in methods:

            def fit_narx(seed=seed):
                m = identify(est, st, rng=seed)
                return sim(m), narx_note(m)

            row(f"NARX({ny}, {n}, {nk}), integrator={k}, default", seed, fit_narx)
        if "narx-holdout0" in methods:

            def fit_h0(seed=seed):
                m = identify(est, st, rng=seed, holdout=0.0)
                return sim(m), narx_note(m)

            row(f"NARX({ny}, {n}, {nk}), holdout=0", seed, fit_h0)
        if "narx-fair" in methods and not k:

            def fit_fair(seed=seed):
                m, rounds = fair_stopping(est, st, seed)
                return sim(m), f"{rounds} rounds chosen"

            row(f"NARX({ny}, {n}, {nk}) oe, fair early stopping", seed, fit_fair)
    if "poly" in methods and k <= 1:
        pn = PolynomialNARX(ny, n, nk, degree=2, n_terms=15, integrator=bool(k))
        row(
            f"PolynomialNARX({ny}, {n}, {nk}) FROLS",
            "-",
            lambda: sim(identify(est, pn)),
        )
    if "sipy" in methods:
        row(
            "SysIdentPy FROLS", "-", lambda: _sipy_frols(est, val, rec.joined, n, nk, k)
        )
    if "sipy-nn" in methods:
        for seed in seeds:
            row(
                "SysIdentPy neural NARX",
                seed,
                lambda seed=seed: _sipy_nn(est, val, rec.joined, n, nk, k, seed),
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", required=True, type=Path, help="folder of record files")
    ap.add_argument("--records", default="", help="names to run (default: all found)")
    ap.add_argument("--methods", default="arx,narx,poly,sipy,sipy-nn")
    ap.add_argument("--orders", default="1,2,3,4,6")
    ap.add_argument(
        "--seeds",
        type=seed_list,
        default="0",
        help="of the NARX and the neural peer: 0-4 or 0,3",
    )
    ap.add_argument("--silverbox-est", type=int, default=17384)
    ap.add_argument("--lags", default="", help='"record=n,k;..." instead of the choice')
    args = ap.parse_args()
    methods = {m.strip() for m in args.methods.split(",")}
    orders = [int(o) for o in args.orders.split(",")]
    given = {}
    for item in filter(None, args.lags.split(";")):
        name, v = item.split("=")
        given[name.strip()] = tuple(int(x) for x in v.split(","))
    records = load_records(args.data, args.silverbox_est)
    if args.records:
        want = {r.strip() for r in args.records.split(",")}
        records = [r for r in records if r.name in want]
    if not records:
        raise SystemExit(f"no record files found in {args.data}")
    with open("/proc/loadavg") as fh:
        print(f"# load average at start: {fh.read().split()[:3]}")
    t0 = time.perf_counter()
    for rec in records:
        run(rec, methods, orders, args.seeds, given.get(rec.name))
    print(f"\n# {time.perf_counter() - t0:.0f} s in all")


if __name__ == "__main__":
    main()
