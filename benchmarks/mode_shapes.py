"""Mode shapes of the simulated rig from a shared-denominator fit, against
the finite elements' shapes: frequencies, MAC and interval coverage.

Setup: ``FlexibleManipulator()`` (the default rig: modal damping 0.02, no
hub friction) and ``paper_experiment()`` with accelerometers at
``--positions`` (default 0.25, 0.5, 0.75 and 1 of the length; the
accelerometers' default noise, 1 m/s^2 each, one noise seed per
realisation), the first 2/3 estimating. ``--input force`` drives the beam
with the shaker alone instead (``force_at`` ``--force-at``, default 0.6;
no torque): the same shapes must come out of either input. ``--input
both``: the torque and the shaker together, a record of two inputs fitted
with one denominator over every pair; the shapes are the torque's
(``model.input_shapes("torque")``).

Structure: ARX(14, 14, 1), every accelerometer's true order (five modes
below Nyquist, 10 poles, and the 4th-order anti-aliasing filter every
accelerometer passes; strictly proper through the filter).

Truth. Frequencies: the FEM's undamped natural frequencies ``rig.modes(3)``
(the sampled model's poles hold them exactly: modal damping).
Shapes: ``rig.mode_shape(k, positions, frame="inertial")``: an
accelerometer at ``x`` reads ``x L theta'' + w''(x)``, the second
derivative of the inertial displacement, and with modal damping each
mode's contribution to every accelerometer is that mode's inertial
displacement at the sensor times a factor common to every sensor (the
input's participation, ``s^2`` at the pole, the sampling and the filter
every accelerometer shares), so the residues over the accelerometers are
the FEM's inertial shape at their positions, exactly, up to one complex
factor. Both are normalised alike (unit norm, largest component positive).

For each realisation: ``identify(est, ARX(14, 14, 1), method=--method)``
(default ``oe``, output error: the shared spiral search ends at its
minimum on this rig, and costs more), each FEM mode matched to the nearest
identified one. Prints per mode: mean and largest frequency error (%),
the coverage of the 95 % frequency interval, the smallest and mean MAC of
the identified shape with the FEM's, the largest off-diagonal MAC with the
other FEM modes (how well the four sensors tell the modes apart), and the
coverage of the 95 % intervals of the shape's components (real and
imaginary parts, the FEM's being real). Then the wall times. Asserts
nothing.

Run: ``python benchmarks/mode_shapes.py [--seeds 20] [--workers 2]
[--positions 0.25,0.5,0.75,1] [--method oe] [--input torque|force|both]
[--force-at 0.6]``.
"""

import os

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import replace

import numpy as np

from spiralid.fms import FlexibleManipulator, paper_experiment
from spiralid.sysid import ARX
from spiralid.sysid import identify as fit
from spiralid.sysid.models.shapes import normalise_shapes

N_MODES = 3
ORDER = (14, 14, 1)


def record(seed: int, positions, source: str, force_at: float):
    """The estimation part of one realisation."""
    exp = replace(paper_experiment(), acceleration_at=tuple(positions))
    if source == "force":
        exp = replace(exp, amplitude=0.0, force_at=force_at)
    elif source == "both":
        exp = replace(exp, force_at=force_at)
    names = list(exp.sensors().positional_names)
    rec = exp.run(FlexibleManipulator(), rng=seed)
    inputs = ["torque", "force"] if source == "both" else source
    return rec.iodata(names, input=inputs).split(2 / 3)[0]


def run_one(task) -> dict:
    seed, positions, method, source, force_at = task
    rig = FlexibleManipulator()
    est = record(seed, positions, source, force_at)
    t0 = time.perf_counter()
    model = fit(est, ARX(*ORDER), method=method, rng=seed)
    elapsed = time.perf_counter() - t0
    table = model.modes.table
    # Two inputs: the shapes the torque excites (the shaker's are the same
    # shapes up to each mode's participation).
    shapes = model.input_shapes("torque") if source == "both" else model.shapes
    fem = np.array(
        [rig.mode_shape(k, positions, frame="inertial") for k in range(1, N_MODES + 1)]
    )
    truth = normalise_shapes(fem)
    out = {"time": elapsed, "error": [], "covers": [], "mac": [], "cross": []}
    out["shape_covers"] = []
    for k, f in enumerate(rig.modes(N_MODES)):
        i = int(np.argmin(np.abs(table.frequency - f)))
        lo, hi = table.frequency_interval[i]
        out["error"].append(100 * abs(table.frequency[i] - f) / f)
        out["covers"].append(bool(lo <= f <= hi))
        macs = shapes.mac(fem)[i]
        out["mac"].append(float(macs[k]))
        out["cross"].append(float(np.delete(macs, k).max()))
        r_lo, r_hi = np.moveaxis(shapes.real_interval[i], -1, 0)
        i_lo, i_hi = np.moveaxis(shapes.imag_interval[i], -1, 0)
        t = truth[k]
        hit = np.r_[(r_lo <= t.real) & (t.real <= r_hi), (i_lo <= 0) & (0 <= i_hi)]
        known = np.all(np.isfinite(np.r_[r_lo, r_hi, i_lo, i_hi]))
        out["shape_covers"].append(hit.astype(float) if known else np.nan)
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--positions", default="0.25,0.5,0.75,1")
    ap.add_argument("--method", default="oe", choices=("oe", "spiral"))
    ap.add_argument("--input", default="torque", choices=("torque", "force", "both"))
    ap.add_argument("--force-at", type=float, default=0.6)
    args = ap.parse_args(argv)
    positions = tuple(float(x) for x in args.positions.split(","))
    rig = FlexibleManipulator()
    fem = np.array(
        [rig.mode_shape(k, positions, frame="inertial") for k in range(1, N_MODES + 1)]
    )
    tasks = [
        (seed, positions, args.method, args.input, args.force_at)
        for seed in range(args.seeds)
    ]
    t0 = time.perf_counter()
    if args.workers > 1:
        with ProcessPoolExecutor(args.workers) as pool:
            runs = list(pool.map(run_one, tasks))
    else:
        runs = [run_one(t) for t in tasks]
    wall = time.perf_counter() - t0
    print(
        f"rig: accelerometers at {positions}, input {args.input}"
        + (f" at {args.force_at:g}" if args.input != "torque" else "")
        + f", ARX{ORDER}, method {args.method}, {args.seeds} seeds"
    )
    print("FEM modes (Hz):", ", ".join(f"{f:.4f}" for f in rig.modes(N_MODES)))
    print("FEM shapes at the sensors (normalised):")
    for k, row in enumerate(normalise_shapes(fem).real, 1):
        print(f"  mode {k}: " + ", ".join(f"{v:+.4f}" for v in row))
    from spiralid.sysid.models.shapes import mac

    print("FEM auto-MAC at the sensors:", np.round(mac(fem), 3).tolist())
    head = (
        "mode | mean freq. error % | max freq. error % | freq. interval covers "
        "| min MAC | mean MAC | max cross-MAC | shape intervals cover"
    )
    print(f"| {head} |")
    print("|---|---|---|---|---|---|---|---|")
    for k in range(N_MODES):
        err = np.array([r["error"][k] for r in runs])
        cov = np.mean([r["covers"][k] for r in runs])
        macs = np.array([r["mac"][k] for r in runs])
        cross = max(r["cross"][k] for r in runs)
        shape_cov = np.mean([r["shape_covers"][k] for r in runs])
        print(
            f"| {k + 1} | {err.mean():.4f} | {err.max():.4f} | {100 * cov:.0f} % | "
            f"{macs.min():.6f} | {macs.mean():.6f} | {cross:.3f} | "
            f"{100 * shape_cov:.0f} % |"
        )
    times = np.array([r["time"] for r in runs])
    print(
        f"fit time: median {np.median(times):.1f} s, max {times.max():.1f} s; "
        f"wall {wall:.0f} s with {args.workers} worker(s); load average "
        f"{os.getloadavg()[0]:.1f}"
    )


if __name__ == "__main__":
    main()
