"""Are the 95 % intervals of the rig's mode frequencies calibrated?

Issue 27's goal: the 95 % intervals of the simulated rig's three mode
frequencies (measurement noise, 100 noise realisations, fitted at the true
order) cover the FEM's frequencies in 90-98 % of the realisations. This
script measures it and prints the coverage tables; it asserts nothing.

Setup
-----
- Plant: ``FlexibleManipulator()``, the default rig (hub inertia 5.86e-4
  kg m^2, 10 elements, no payload, no friction, modal damping 0.02).
- Truth: ``rig.modes(3)``, 13.3105, 35.1080 and 64.8340 Hz, the undamped
  natural frequencies of the flexible modes of the very model ``simulate``
  integrates: the beam clamped to a hub that turns freely with its own
  inertia (neither pinned nor clamped at the hub; the rigid mode is the
  zero-frequency one, left out). The damping is modal, ``C = M Phi diag(2
  zeta w_i) Phi^T M``, so each continuous pole pair is ``-zeta w_i +- j w_i
  sqrt(1 - zeta^2)`` with ``|s| = w_i`` and ``zeta = 0.02`` exactly: the
  ModeTable's natural frequency (``|ln p| / ts``) and damping ratio compare
  with them directly, and the sampled model's eigenvalues reproduce them to
  1e-12 (the exact zero-order-hold discretisation keeps ``p = e^{s ts}``).
- Record: ``paper_experiment()`` (six bang-bang pulses, 6 s at 500 Hz),
  end-point acceleration through the default sensors: 4th-order Butterworth
  anti-aliasing at 87.5 Hz and white accelerometer noise of 1 m/s^2 (the
  record's RMS is 49 m/s^2). The noise is added after sampling, white and
  Gaussian: output error's own noise model, so its ``s^2 (J^T J)^-1`` is
  the right covariance whenever the structure holds the plant. Every
  realisation has the same torque and fresh noise (one child of a
  ``SeedSequence`` per realisation; ``spiral`` gets another). The first 2/3
  (2,000 samples) estimate, as in the paper and the README.
- Each (order, method): ``identify(est, ARX(...), method=...)`` with
  ``"oe"`` and the default ``"spiral"``; each FEM mode is matched to the
  identified mode nearest in frequency; recorded: frequency and damping
  error, their standard errors and whether the 95 % interval
  (``ModeTable.frequency_interval`` / ``damping_interval``) covers the FEM
  value. Each (order, method) is also fitted once to the noise-free record:
  its error there is the structure's bias (unmodelled dynamics), which no
  amount of averaging removes.

The true order
--------------
What the sampled acceleration holds, piece by piece:

- the rigid body: torque gives the hub an angular acceleration ``u / J``, so
  its contribution to the end-point acceleration is a constant gain (direct
  feedthrough); the double pole at ``s = 0`` is not observable in an
  acceleration. No pole.
- three flexible modes (13, 35, 65 Hz): 6 poles.
- the anti-aliasing filter: 4 poles, and relative degree 4, so the sampled
  response has no ``b_0 u(t)`` term: ``nk = 1``.
- the zero-order hold: keeps the ``n`` poles (``p = e^{s ts}``) and gives
  ``n - 1`` zeros; with ``nk = 1`` that is ``nb = n``.

That is ARX(10, 10, 1). But the record holds more than three modes: the
fourth (116 Hz) loses only 10 dB to the filter and its resonant peak in
the acceleration is 14-21 % of each of the first three's; the fifth
(188 Hz, -27 dB) 1.3-1.9 %; the sixth (280 Hz) is above Nyquist and 40 dB
down. Fitted by output error to the noise-free record (misfit as a share
of the noise's variance, 1 m^2/s^4):

- ARX(8, 8, 0): three modes and a damped pair at 99 Hz; misfit 3.1 times
  the noise's variance.
- ARX(10, 10, 1): spends two poles on the fourth mode and squeezes the
  filter into one damped pair (86.6 Hz, zeta 0.43); misfit 2 %, and the
  third frequency's noise-free bias is 0.5 standard error.
- ARX(11, 11, 1): the same and a real pole; misfit 1.5 %, frequency
  biases at most 0.04 se.
- ARX(12, 12, 1): every mode below Nyquist (13, 35, 65, 116 and 188 Hz,
  each at zeta 0.020) and the filter as one pair (88 Hz, zeta 0.39);
  misfit 0.01 %, and the noise-free biases of the three frequencies and
  dampings are below 0.1 standard error.

No order below the simulator's 44 holds the record exactly. **ARX(12, 12,
1) is the lowest order that holds every resonance of the record (all five
modes below Nyquist) besides the filter**, with a misfit over 100 times
smaller than orders 10 and 11 leave, and it is the "true order" here.
ARX(10, 10, 1), the three-modes-and-filter count, runs with ``--orders
10,10,1`` (the slowest: output error crawls along a long valley, about 5 s
of CPU per fit against 0.3-3 s at order 12); the paper's ARX(8, 8, 0) runs
beside the true order by default.

Results
-------
``python benchmarks/mode_intervals.py`` (100 realisations, 2 workers:
620-658 s on 2 shared cores, load average 2-7 at the start;
``--realisations 50`` halves it). Coverage of the three frequencies' 95 %
intervals (exact 95 % CI of a coverage from 100 realisations: about +-5
points):

- **ARX(12, 12, 1), the true order: calibrated.** Output error 93, 97,
  94 %; ``spiral`` 93, 96, 93 %; damping 97, 92, 95 % and 96, 94, 95 %.
  Bias at most 0.16 se, mean se / Monte Carlo sd 0.93-1.07: the interval
  is as wide as the realisations' spread, not merely narrow.
- **ARX(8, 8, 0), the paper's order: not calibrated, because of bias.**
  89, 74 and 3 % for both methods (the same optimum every time). The
  structure's noise-free bias is -1.22, +3.42 and -23.98 mHz = -1.4, +1.5
  and -3.1 se (se 0.89, 2.24 and 7.62 mHz), and the realisations' mean
  bias is the same (-1.26, +3.46, -23.86 mHz): unmodelled dynamics (the
  fourth mode and the filter), which no interval from ``s^2 (J^T J)^-1``
  accounts for. The se is also 1.8-1.9x the realisations' sd (``s^2``
  holds the deterministic misfit, 3.1 times the noise's variance, besides
  the noise), so the damping intervals, whose bias is smaller, over-cover
  (98-100 %).
- ARX(10, 10, 1) (``--orders 10,10,1 --realisations 50``, 368 s): 94, 96
  and 92 % (damping 98, 92, 94 %), both methods; mode 3's noise-free bias
  +1.9 mHz = 0.5 se predicts 91 %: inside the band, at its edge.

``spiral``'s cost equals output error's (median ratio 1.000000) and is
never above it; at ARX(12, 12, 1) it is lower in some realisations (down
to 0.989 x): there output error can stop with a pole pair on the stability
margin (realisation 12: a 214 Hz "mode", damping 0.0002, flagged as
reaching ``|z| = 1``). The three modes' intervals are the same either way.

Two defects of the library found on the way (reported, not fixed here):

- The delta method loses the first mode's variance to rounding when
  ``J`` is ill-conditioned: it forms the coefficient covariance ``s^2 V
  S^-2 V^T`` explicitly (condition ``cond(J)^2``) and then ``g^T C g``. On
  the acceleration at ARX(12, 12, 1) (``cond(J)`` 1.5-5e8) the se agree
  with ``s^2 ||S^-1 V^T g||^2`` to 0.05 %; on the hub velocity at
  ARX(11, 11, 1) with ``integrator=True`` (``cond(J)`` 2-3e9) the first
  mode's se is 0, 0.04, 0.50 or 0.60 mHz where the exact value is 0.13 mHz
  (seeds 1, 0, 3, 2), and exactly 0 in several realisations.
- ``ModeTable.share`` sums ``|r| / (1 - |p|)`` over every pole, real ones
  included; a real pole near the origin (``spiral``'s ARX(12, 12, 1) model
  of realisation 12 has one at -6e-11) gets a residue of order ``1 / p``,
  the shares of the true modes fall to 1e-8 and all are flagged "probably
  spurious" (the one count in the ``spiral`` table).

Other outputs
-------------
``--output hub_velocity`` fits the tachometer channel (noise 0.01 rad/s)
with ``integrator=True``: the hub velocity integrates the torque (the
rigid mode's pole at ``z = 1``, known), plus three modes and the filter;
default orders ARX(11, 11, 1) and ARX(13, 13, 1), ``na`` counting the
integrator. With ``--methods oe --realisations 30`` (365 s) the
frequencies' coverage was 67, 83, 87 % and 83, 93, 90 %: not a measure of
calibration, because the first mode's se is the rounding of the defect
above (its mean se is 5x the realisations' sd at order 11, yet it covers
67 %), and order 11 also carries a structural bias (0.6 se in the second
and third frequency, 2.3 se in the third damping). The hub angle does not
apply: the encoder's only error is its quantisation, a deterministic
function of the angle, so every realisation would be the same record (and
the angle integrates twice).

Run: ``python benchmarks/mode_intervals.py [--realisations 100]
[--orders 8,8,0/12,12,1] [--methods oe,spiral] [--output end_acceleration]
[--workers 2] [--seed 0]``.
"""

from __future__ import annotations

import argparse
import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
from scipy import stats

from spiralid.fms import FlexibleManipulator, paper_experiment
from spiralid.sysid import ARX, identify

N_MODES = 3
Z95 = float(stats.norm.ppf(0.975))
DEFAULT_ORDERS = {
    "end_acceleration": "8,8,0/12,12,1",
    "hub_velocity": "11,11,1/13,13,1",
}
# A matched mode further than this share from the FEM's is reported as
# missed (the model has no mode there).
MISSED_SHARE = 0.05


def parse_orders(text: str) -> list[tuple[int, int, int]]:
    """``"8,8,0/12,12,1"`` -> ``[(8, 8, 0), (12, 12, 1)]``."""
    orders = []
    for part in text.split("/"):
        na, nb, nk = (int(v) for v in part.split(","))
        orders.append((na, nb, nk))
    return orders


def records(output: str, noise_seed):
    """The estimation part of one record: noise-free when `noise_seed` is
    None, else with the experiment's sensor noise drawn from it."""
    rig = FlexibleManipulator()
    exp = paper_experiment()
    if noise_seed is None:
        sensors = replace(exp.sensors(), accel_noise=0.0, tach_noise=0.0)
        rec = rig.simulate(exp.torque(), fs=exp.fs, sensors=sensors)
    else:
        rec = exp.run(rig, rng=np.random.default_rng(noise_seed))
    return rec.iodata(output).split(2 / 3)[0]


def fit(est, order, method: str, search_seed, output: str) -> dict:
    """One identification and its three matched modes."""
    truth = FlexibleManipulator().modes(N_MODES)
    t0 = time.perf_counter()
    model = identify(
        est,
        ARX(*order),
        method=method,
        rng=np.random.default_rng(search_seed),
        integrator=output == "hub_velocity",
    )
    seconds = time.perf_counter() - t0
    modes = model.modes
    row = {
        "cost": float(model.cost),
        "effective": tuple(model.effective_order),
        "seconds": seconds,
        "n_modes": len(modes),
    }
    if not len(modes):
        nan = np.full(N_MODES, np.nan)
        row.update(f=nan, f_se=nan, z=nan, z_se=nan, f_int=np.c_[nan, nan])
        row.update(z_int=np.c_[nan, nan], spurious=np.zeros(N_MODES, bool))
        return row
    idx = np.argmin(np.abs(modes.frequency[None, :] - truth[:, None]), axis=1)
    row.update(
        f=modes.frequency[idx],
        f_se=modes.frequency_se[idx],
        f_int=modes.frequency_interval[idx],
        z=modes.damping[idx],
        z_se=modes.damping_se[idx],
        z_int=modes.damping_interval[idx],
        spurious=modes.spurious[idx],
    )
    return row


def realisation(task) -> tuple[int, dict]:
    """Every (order, method) on realisation `k`'s record."""
    k, seeds, orders, methods, output = task
    noise_seed, search_seed = seeds
    est = records(output, noise_seed)
    rows = {}
    for order in orders:
        for method in methods:
            rows[order, method] = fit(est, order, method, search_seed, output)
    return k, rows


def coverage_ci(hits: int, n: int) -> tuple[float, float]:
    """Exact (Clopper-Pearson) 95 % interval of a coverage, in %."""
    ci = stats.binomtest(hits, n).proportion_ci(0.95, method="exact")
    return 100 * ci.low, 100 * ci.high


def predicted_coverage(bias: float, se: float, sd: float) -> float:
    """Coverage of ``est +- 1.96 se`` if ``est ~ N(truth + bias, sd^2)``, %."""
    half = Z95 * se
    return 100 * float(
        stats.norm.cdf((half - bias) / sd) - stats.norm.cdf((-half - bias) / sd)
    )


def summarise(rows: list[dict], clean: dict, truth, zeta, label: str):
    """Print the frequency and damping tables of one (order, method)."""
    n = len(rows)
    stacked = {
        key: np.array([r[key] for r in rows])
        for key in ("f", "f_se", "f_int", "z", "z_se", "z_int", "spurious")
    }
    seconds = np.array([r["seconds"] for r in rows])
    effective = {r["effective"] for r in rows}
    print(
        f"\n{label}: {n} realisations, median {np.median(seconds):.1f} s per fit "
        f"(max {seconds.max():.1f}); effective orders "
        f"{', '.join(f'ARX{e}' for e in sorted(effective))}"
    )
    notes = []
    for what, key, fem, scale, unit in (
        ("frequency", "f", truth, 1e3, "mHz"),
        ("damping", "z", np.full(N_MODES, zeta), 1e4, "x1e-4"),
    ):
        est, se, interval = stacked[key], stacked[f"{key}_se"], stacked[f"{key}_int"]
        covered = (interval[:, :, 0] <= fem) & (fem <= interval[:, :, 1])
        print(
            f"  {what}: bias, se and sd in {unit}; coverage of the 95 % "
            "interval [its exact 95 % CI]; predicted: the coverage a normal "
            "estimate with this bias, sd and se would have"
        )
        fem_head = "FEM Hz" if key == "f" else "FEM zeta"
        print(
            f"  | mode | {fem_head} | mean identified | bias | noise-free bias "
            "| mean se | MC sd | bias / se | se / sd | coverage % | predicted % |"
        )
        print("  |---|---|---|---|---|---|---|---|---|---|---|")
        for i in range(N_MODES):
            ok = np.isfinite(est[:, i]) & np.isfinite(se[:, i])
            bias = float(np.mean(est[ok, i]) - fem[i])
            sd = float(np.std(est[ok, i], ddof=1)) if ok.sum() > 1 else np.nan
            mse = float(np.mean(se[ok, i]))
            hits = int(covered[:, i].sum())
            lo, hi = coverage_ci(hits, n)
            cov = 100 * hits / n
            nf_bias = float(clean[key][i] - fem[i])
            pred = predicted_coverage(bias, mse, sd) if sd > 0 else np.nan
            print(
                f"  | {i + 1} | {fem[i]:.4f} | {np.mean(est[ok, i]):.4f} "
                f"| {scale * bias:+.3f} | {scale * nf_bias:+.3f} "
                f"| {scale * mse:.3f} | {scale * sd:.3f} | {bias / mse:+.2f} "
                f"| {mse / sd:.2f} | {cov:.0f} [{lo:.0f}, {hi:.0f}] | {pred:.0f} |"
            )
            if not 90.0 <= cov <= 98.0:
                notes.append(_diagnosis(what, i, cov, bias, nf_bias, mse, sd, scale, n))
    missed = np.abs(stacked["f"] - truth) > MISSED_SHARE * truth
    spurious = stacked["spurious"].sum(axis=0)
    # A standard error of exactly 0 is the delta method's rounding (see the
    # module docstring), not a certain frequency.
    zero_se = (stacked["f_se"] == 0).sum(axis=0)
    print(
        "  per FEM mode: matched mode missed (> 5 % off) "
        f"{missed.sum(axis=0).tolist()}; flagged probably spurious "
        f"{spurious.tolist()}; frequency se exactly 0 {zero_se.tolist()}"
    )
    for note in notes:
        print(f"  * {note}")


def _diagnosis(what, i, cov, bias, nf_bias, se, sd, scale, n) -> str:
    """One line on why a coverage is outside 90-98 %."""
    unit = "mHz" if what == "frequency" else "x1e-4"
    head = f"mode {i + 1} {what}: coverage {cov:.0f} % is outside 90-98 %"
    why = []
    if abs(nf_bias) > 0.5 * se:
        why.append(
            f"bias {scale * bias:+.3f} {unit} = {bias / se:+.1f} se, "
            f"noise-free {scale * nf_bias:+.3f} {unit} = {nf_bias / se:+.1f} se: "
            "unmodelled dynamics, which the interval does not account for"
        )
    elif abs(bias) > max(0.5 * se, 2 * sd / np.sqrt(n)):
        why.append(
            f"bias {scale * bias:+.3f} {unit} = {bias / se:+.1f} se against "
            f"{scale * nf_bias:+.3f} noise-free: a bias the noise itself causes"
        )
    # The sample sd's relative standard error is about 1 / sqrt(2 (n - 1)).
    spread = 2 / np.sqrt(2 * (n - 1))
    if abs(se / sd - 1) > spread:
        side = "narrow" if se < sd else "wide"
        why.append(
            f"the se ({scale * se:.3f}) is {se / sd:.2f} of the Monte Carlo "
            f"sd ({scale * sd:.3f} {unit}): the interval is too {side}"
        )
    if not why:
        why.append(
            f"bias {bias / se:+.2f} se and se / sd {se / sd:.2f} are within "
            "the Monte Carlo error"
        )
    return f"{head}: " + "; ".join(why)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--realisations", type=int, default=100)
    ap.add_argument(
        "--orders", default=None, help="na,nb,nk/na,nb,nk (default per output)"
    )
    ap.add_argument("--methods", default="oe,spiral")
    ap.add_argument(
        "--output", default="end_acceleration", choices=sorted(DEFAULT_ORDERS)
    )
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    orders = parse_orders(args.orders or DEFAULT_ORDERS[args.output])
    methods = args.methods.split(",")
    t_start = time.perf_counter()
    load = os.getloadavg()[0]

    rig = FlexibleManipulator()
    truth = rig.modes(N_MODES)
    zeta = rig.damping_ratio
    print(
        f"Rig: FEM modes {', '.join(f'{f:.4f}' for f in truth)} Hz "
        f"(FlexibleManipulator().modes(3): hub free with its inertia), modal "
        f"damping {zeta}; output {args.output}, paper_experiment() with its "
        "sensor noise, first 2/3 estimates"
    )

    # The structure's bias: each (order, method) on the noise-free record.
    clean_est = records(args.output, None)
    clean = {}
    for order in orders:
        for method in methods:
            clean[order, method] = fit(clean_est, order, method, 0, args.output)

    children = np.random.SeedSequence(args.seed).spawn(args.realisations)
    tasks = [
        (k, tuple(child.spawn(2)), orders, methods, args.output)
        for k, child in enumerate(children)
    ]
    results: dict[int, dict] = {}
    if args.workers > 1:
        with ProcessPoolExecutor(args.workers) as pool:
            for k, rows in pool.map(realisation, tasks):
                results[k] = rows
    else:
        for task in tasks:
            k, rows = realisation(task)
            results[k] = rows

    for order in orders:
        for method in methods:
            rows = [results[k][order, method] for k in sorted(results)]
            label = f"ARX{order}, method {method!r}"
            summarise(rows, clean[order, method], truth, zeta, label)
    if "oe" in methods and "spiral" in methods:
        for order in orders:
            ratio = np.array(
                [
                    results[k][order, "spiral"]["cost"]
                    / results[k][order, "oe"]["cost"]
                    for k in sorted(results)
                ]
            )
            print(
                f"\nARX{order}: spiral's cost / OE's over the realisations: "
                f"median {np.median(ratio):.6f}, min {ratio.min():.6f}, "
                f"max {ratio.max():.6f}"
            )
    wall = time.perf_counter() - t_start
    print(
        f"\nWall time {wall:.0f} s ({args.workers} workers, "
        f"{args.realisations} realisations); load average at start {load:.1f}"
    )


if __name__ == "__main__":
    main()
