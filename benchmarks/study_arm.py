"""What the spiral methods reach: a known ARX(2, 2, 1) and the real flexible arm.

Prints two tables (issue 4's experiments):

1. Noise-free ARX(2, 2, 1) (600 samples, white input, seed 11), 10 seeds:
   SDA and Eb-SDA, both parametrisations, plain and refined.
2. The real flexible arm (DaISy 96-009, ``ts = 0.01`` s, a documented choice:
   the source gives none), ARX(8, 8, 0), simulation cost, 50 points x 500
   iterations, 5 seeds: SDA and Eb-SDA, both parametrisations, with and
   without ``refine``; least squares and output error for reference. Once
   with the simulation started from rest (``initial="rest"``, the default)
   and once from the measured past (``initial="measured"``, the rule for a
   record that starts in motion, as this one does).

Columns: the paper's cost eq. (2)-(3) on the estimation part (percent RMS
error, ``gain="auto"``, under the table's ``initial``) and the validation
fit (MATLAB ``compare`` NRMSE, %) of a free-run simulation of the whole
record from rest, scored on the last third. Paper constants untouched. Run:
``.venv/bin/python benchmarks/study_arm.py [n_seeds_arm]``;
``.venv/bin/python benchmarks/study_arm.py oe`` instead prints the
output-error initial-state study (:func:`oe_initial_state_study`).
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import sys
from pathlib import Path

import numpy as np
from scipy.signal import lfilter

import spiralid.datasets
from spiralid.sysid import ARX, IOData, PaperCost, identify, is_stable_polynomial

# The DaISy arm record shipped with the package (spiralid.datasets).
ARM = Path(spiralid.datasets.__file__).with_name("daisy_robot_arm.csv")


def fit_percent(y, yhat):
    return 100.0 * (1.0 - np.linalg.norm(y - yhat) / np.linalg.norm(y - np.mean(y)))


def score(model, data):
    est, val = data.split()
    with np.errstate(all="ignore"):
        yhat = model.simulate(data.u)[est.n :]
    return model.cost, fit_percent(val.y, yhat) if np.all(
        np.isfinite(yhat)
    ) else -np.inf


def fmt(values):
    v = np.asarray(values, dtype=float)
    return f"{np.median(v):9.2f} [{np.min(v):9.2f}, {np.max(v):9.2f}]"


def table(title, data, arx, seeds, configs, initial="rest", **opts):
    print(f"\n{title}; initial={initial!r}")
    est, _ = data.split()
    for method in ("ls", "oe"):
        ref = identify(est, arx, method=method, initial=initial)
        cost, fit = score(ref, data)
        print(
            f"  {method:<34} cost {cost:9.3f}   val fit {fit:9.2f} %   "
            f"max|pole| {np.abs(ref.poles).max():.6f}"
        )
    head = ("method / parametrisation / refine", "cost median [min, max]")
    print(f"  {head[0]:<34} {head[1]:<33} val fit % median [min, max]")
    for method, par, refine in configs:
        costs, fits, stable, radius = [], [], 0, []
        for seed in seeds:
            model = identify(
                est, arx, method=method, parametrization=par, refine=refine,
                rng=seed, initial=initial, **opts,
            )  # fmt: skip
            c, f = score(model, data)
            costs.append(c)
            fits.append(f)
            stable += model.is_stable
            radius.append(np.abs(model.poles).max())
        label = f"{method} / {par} / {'refine' if refine else 'plain'}"
        print(
            f"  {label:<34} {fmt(costs)}   {fmt(fits)}   stable {stable}/{len(seeds)}"
        )
        print(f"  {'':<34} per seed fit: {' '.join(f'{x:.1f}' for x in fits)}")
        print(f"  {'':<34} per seed max|pole|: {' '.join(f'{x:.6f}' for x in radius)}")


def feasibility() -> None:
    """How often is a uniform draw in a coefficient box stable (na = 8)?"""
    from math import comb

    rng = np.random.default_rng(0)
    half = np.array([comb(8, i) for i in range(1, 9)], dtype=float)
    n = 20000
    print("\nStable fraction of uniform denominators, na = 8, 20000 draws (rng 0)")
    for label, box in (("|a_i| <= binom(8, i)", half), ("[-1, 1]^8", np.ones(8))):
        a = rng.uniform(-box, box, size=(n, 8))
        print(f"  {label:<22} {100 * is_stable_polynomial(a).mean():6.2f} %")


def main() -> None:
    n_arm = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    feasibility()
    configs = [
        (m, p, r)
        for p in ("coefficients", "reflection")
        for m in ("sda", "ebsda")
        for r in (False, True)
    ]
    u = np.random.default_rng(11).standard_normal(600)
    known = IOData(u, lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u), ts=0.01)
    table(
        "Known ARX(2, 2, 1), noise-free, 600 samples; 10 seeds; "
        "50 points x 500 iterations",
        known, ARX(2, 2, 1), range(10), configs,
    )  # fmt: skip
    if not ARM.exists():
        print(f"\n(real arm data not found at {ARM})")
        return
    arm = IOData.from_csv(ARM, input="u", output="y", ts=0.01)
    for initial in ("rest", "measured"):
        table(
            f"Real flexible arm, ARX(8, 8, 0), simulation cost; {n_arm} seeds; "
            "50 points x 500 iterations",
            arm, ARX(8, 8, 0), range(n_arm), configs, initial=initial,
        )  # fmt: skip
    gain_table(arm, ARX(8, 8, 0), range(n_arm))


def gain_table(data, arx, seeds):
    """Eb-SDA's radius and angle see |f - min J| (eq. (4)), so the gain w of
    eq. (2) changes the search itself (DESIGN.md item 13)."""
    est, _ = data.split()
    auto = PaperCost(arx, est, predictor="simulation")
    print(
        "\nEb-SDA sensitivity to the gain w (cost shown on the auto scale, "
        "percent RMS error); plain search; initial='rest'"
    )
    for par in ("coefficients", "reflection"):
        for factor in (0.1, 1.0, 10.0):
            costs, fits = [], []
            for seed in seeds:
                model = identify(
                    est, arx, method="ebsda", parametrization=par,
                    gain=factor * auto.w, rng=seed,
                )  # fmt: skip
                costs.append(auto(model.theta))
                fits.append(score(model, data)[1])
            label = f"ebsda / {par} / w = {factor:g} x auto"
            print(f"  {label:<34} {fmt(costs)}   {fmt(fits)}")


def _oe_variant(data, arx, theta0, initial, kmax=1.0 - 1e-6):
    """Output error under another initial-state rule (finite differences;
    a study, not the library's method).

    ``"estimated"``: the na outputs before ``t0`` are free parameters
    (MATLAB's ``InitialCondition='estimate'``); ``"rest-from-t0"``: zero
    state at ``t = 0``, scored from ``t0`` on (the library's
    ``initial="rest"`` scores all N samples). Returns (theta, rms of the
    criterion's error)."""
    from scipy import optimize, signal

    from spiralid.sysid import step_up
    from spiralid.sysid.estimation.linear.parametrizations import stabilise

    na, t0 = arx.na, arx.max_lag
    ulags = arx.input_lags(data.u)
    y = data.y

    def unpack(x):
        return step_up(kmax * np.tanh(x[:na])), x[na : arx.n_params]

    def residual(x):
        a, b = unpack(x)
        den = np.r_[1.0, a]
        if initial == "rest-from-t0":
            return signal.lfilter([1.0], den, b @ ulags)[t0:] - y[t0:]
        zi = signal.lfiltic([1.0], den, x[arx.n_params :])
        return signal.lfilter([1.0], den, b @ ulags[:, t0:], zi=zi)[0] - y[t0:]

    start = stabilise(theta0, arx)
    k = np.clip(start[:na] / kmax, -1 + 1e-12, 1 - 1e-12)
    x0 = np.r_[np.arctanh(k), start[na:]]
    if initial == "estimated":
        x0 = np.r_[x0, y[t0 - na : t0][::-1]]
    res = optimize.least_squares(
        residual, x0, method="lm", x_scale="jac", xtol=1e-12, ftol=1e-12,
        gtol=1e-12, max_nfev=3000,
    )  # fmt: skip
    a, b = unpack(res.x)
    return np.r_[a, b], float(np.sqrt(np.mean(res.fun**2)))


def oe_initial_state_study() -> None:
    """Why "oe" validates below least squares on the real arm (issue 4).

    For the arm and the simulated rig (``spiralid.reproduction.default_data()``),
    ARX(8, 8, 0): output error under four initial-state rules, each from
    the least-squares and the Steiglitz-McBride start: the library's
    ``initial="rest"`` and ``"measured"``, and two study variants
    (:func:`_oe_variant`); then the reflection bound kmax of the library's
    measured-past criterion. Columns: the paper's cost from rest and from
    the measured past, the criterion's own RMS error, the validation fit
    (from rest over the whole record, last third) and the largest pole
    radius.
    """
    import spiralid.sysid.estimation.linear.outputerror as mod
    from spiralid.sysid import (
        IdentifiedModel,
        arx_least_squares,
        steiglitz_mcbride,
        validate,
    )

    arx = ARX(8, 8, 0)
    records = {}
    if ARM.exists():
        records["arm"] = IOData.from_csv(ARM, input="u", output="y", ts=0.01).split()
    try:
        from spiralid.reproduction import default_data

        records["rig"] = default_data().split()
    except ImportError:
        pass
    print("\nOutput error: initial-state rule x start (ARX(8, 8, 0))")
    for name, (est, val) in records.items():
        rest = PaperCost(arx, est, initial="rest")
        measured = PaperCost(arx, est, initial="measured")
        ls = arx_least_squares(est, arx)
        starts = {"ls": ls, "sm": steiglitz_mcbride(est, arx, ls)}
        for sname, start in starts.items():
            for initial in ("rest", "measured", "estimated", "rest-from-t0"):
                if initial in ("rest", "measured"):
                    theta, res = mod.local_polish(
                        start, arx, est, "simulation", initial
                    )
                    own = float(np.sqrt(np.mean(res.fun**2)))
                else:
                    theta, own = _oe_variant(est, arx, start, initial)
                model = IdentifiedModel(theta, arx, est.ts, method="oe")
                fit = validate(model, val, warmup=est).fit_percent
                print(
                    f"  {name} start {sname:<2} initial {initial:<12} paper cost "
                    f"rest {rest(theta):9.4f} measured {measured(theta):9.4f}  "
                    f"criterion rms {own:10.5g}  val fit {fit:6.2f} %  "
                    f"max|pole| {np.abs(model.poles).max():.7f}"
                )
    if "arm" in records:
        est, val = records["arm"]
        print("  arm, measured-past criterion from least squares, bound on |k|:")
        saved = mod.KMAX
        try:
            for kmax in (1 - 1e-6, 1 - 1e-4, 1 - 1e-3, 1 - 1e-2):
                mod.KMAX = kmax
                theta, _ = mod.local_polish(
                    arx_least_squares(est, arx), arx, est, "simulation", "measured"
                )
                model = IdentifiedModel(theta, arx, est.ts, method="oe")
                fit = validate(model, val, warmup=est).fit_percent
                print(
                    f"    kmax 1 - {1 - kmax:.0e}: paper cost "
                    f"{PaperCost(arx, est, initial='measured')(theta):.4f}  "
                    f"val fit {fit:.2f} %  "
                    f"max|pole| {np.abs(model.poles).max():.7f}"
                )
        finally:
            mod.KMAX = saved


if __name__ == "__main__":
    if sys.argv[1:2] == ["oe"]:
        oe_initial_state_study()
    else:
        main()
