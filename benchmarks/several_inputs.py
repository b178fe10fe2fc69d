"""Two inputs, one denominator: the shared fit of a two-input record of the
simulated rig against the fits that use one input only, and N4SID.

Record: the rig (``FlexibleManipulator()``, ``paper_experiment()``, the
sensors' default noise) run twice, the outputs summed: the paper's torque
and a second bang-bang torque of the same amplitude and pulse width with
random signs (sensor noise seeds ``s`` and ``s + 1000``): a second hub
motor beside the first, every input-output pair over the rig's modes
(``y = G u1 + G u2`` plus both runs' sensor noise; the rig's own second
actuator, a point force along the beam, would give each input its own
numerators). White noise of 1 % of its RMS is added to
the tip deflection, which the rig records noise-free (as in
``benchmarks/shared_modes.py``). The first 2/3 estimate, the rest
validates (the model run over the estimation part first, ``warmup``).

Fits, every one ``identify(est, ARX(12, 12, 1))`` by ``--method``
(default the spiral), outputs ``end_acceleration, tip_deflection``:

- ``both inputs``: the shared denominator over every input-output pair;
- ``input k only``: the shared denominator of the record's input k alone
  (the other input's response is then noise to it), validated on that
  input alone;
- ``N4SID`` (nfoursid, the ``bench`` extra; skipped when missing): the
  same two-input estimation record, order ``na``, ``--block-rows`` block
  rows, its state-space model run from rest over the whole record.

Prints each output's validation fit (%) per fit, and the wall times: the
two-input fit against the sum of the one-input fits (the goal: at most
twice it). Times are measured on whatever machine runs it (on a shared
one they vary). Asserts nothing.

Run: ``python benchmarks/several_inputs.py [--seeds 3] [--method spiral]
[--order 12,12,1] [--block-rows 20]``.
"""

import os

if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import time

import numpy as np

from spiralid.fms import FlexibleManipulator, paper_experiment
from spiralid.sysid import ARX, IOData, identify, validate

OUTPUTS = ("end_acceleration", "tip_deflection")


def second_torque(exp, seed: int) -> np.ndarray:
    """Bang-bang torque of the paper's amplitude and pulse width, each
    pulse's sign drawn at random (independent of the paper's train)."""
    first = exp.torque()
    width = round(exp.width * exp.fs)
    signs = np.random.default_rng([seed, 50]).choice(
        [-1.0, 1.0], -(-first.size // width)
    )
    return np.abs(first).max() * np.repeat(signs, width)[: first.size]


def two_input_record(seed: int) -> IOData:
    """The rig's two runs with independent torques, outputs summed."""
    rig, exp = FlexibleManipulator(), paper_experiment()
    one = exp.run(rig, rng=seed).iodata(list(OUTPUTS))
    two = rig.simulate(
        second_torque(exp, seed), fs=exp.fs, rng=seed + 1000, sensors=exp.sensors()
    ).iodata(list(OUTPUTS))
    y = one.outputs + two.outputs
    k = OUTPUTS.index("tip_deflection")
    rms = np.sqrt(np.mean(y[:, k] ** 2))
    y[:, k] += 0.01 * rms * np.random.default_rng([seed, 30]).standard_normal(one.n)
    return IOData(
        np.column_stack([one.u, two.u]),
        y,
        ts=one.ts,
        input_name=("torque_1", "torque_2"),
        output_name=OUTPUTS,
    )


def _fits(model, val, est) -> np.ndarray:
    v = validate(model, val, warmup=est)
    return np.array([v.outputs[name].fit_percent for name in OUTPUTS])


def n4sid_fits(est: IOData, val: IOData, order: int, rows: int) -> np.ndarray | None:
    """nfoursid's N4SID of order `order` on `est`, run from rest over the
    whole record; each output's validation fit (%); None without nfoursid."""
    try:
        import pandas as pd
        from nfoursid.nfoursid import NFourSID
    except ImportError:
        return None
    frame = pd.DataFrame(
        np.column_stack([est.inputs, est.outputs]), columns=["u1", "u2", *OUTPUTS]
    )
    n4 = NFourSID(frame, output_columns=list(OUTPUTS), input_columns=["u1", "u2"],
                  num_block_rows=rows)  # fmt: skip
    n4.subspace_identification()
    ss, _ = n4.system_identification(rank=order)
    u = np.r_[est.inputs, val.inputs]
    x = np.zeros(ss.a.shape[0])
    y = np.empty((u.shape[0], len(OUTPUTS)))
    for t, ut in enumerate(u):
        y[t] = ss.c @ x + ss.d @ ut
        x = ss.a @ x + ss.b @ ut
    y = y[est.n :]
    meas = val.outputs
    miss = np.linalg.norm(meas - y, axis=0) / np.linalg.norm(
        meas - meas.mean(0), axis=0
    )
    return 100 * (1 - miss)


def run(seed: int, method: str, arx: ARX, rows: int) -> dict:
    data = two_input_record(seed)
    est, val = data.split(2 / 3)
    out, times = {}, {}
    t0 = time.perf_counter()
    both = identify(est, arx, method=method, rng=seed)
    times["both inputs"] = time.perf_counter() - t0
    out["both inputs"] = _fits(both, val, est)
    for k, name in enumerate(data.input_names):
        t0 = time.perf_counter()
        one = identify(est.input(name), arx, method=method, rng=seed)
        times[f"input {k + 1} only"] = time.perf_counter() - t0
        out[f"input {k + 1} only"] = _fits(one, val.input(name), est.input(name))
    t0 = time.perf_counter()
    peer = n4sid_fits(est, val, arx.na, rows)
    if peer is not None:
        times["N4SID"] = time.perf_counter() - t0
        out["N4SID"] = peer
    return dict(fits=out, times=times)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--method", default="spiral")
    parser.add_argument("--order", default="12,12,1")
    parser.add_argument("--block-rows", type=int, default=20)
    args = parser.parse_args(argv)
    arx = ARX(*(int(v) for v in args.order.split(",")))
    runs = [run(s, args.method, arx, args.block_rows) for s in range(args.seeds)]
    names = list(runs[0]["fits"])
    print(f"{args.seeds} seeds, {arx}, method {args.method}; validation fit % "
          "(mean over seeds; min in brackets)")  # fmt: skip
    print(f"{'fit':<16}" + "".join(f"{o:>26}" for o in OUTPUTS) + f"{'time (s)':>12}")
    for name in names:
        fits = np.array([r["fits"][name] for r in runs])
        secs = np.mean([r["times"][name] for r in runs])
        cells = "".join(
            f"{fits[:, k].mean():>18.2f} [{fits[:, k].min():5.2f}]"
            for k in range(len(OUTPUTS))
        )
        print(f"{name:<16}{cells}{secs:>12.1f}")
    both = np.array([r["fits"]["both inputs"] for r in runs])
    best = np.array(
        [np.maximum(r["fits"]["input 1 only"], r["fits"]["input 2 only"]) for r in runs]
    )
    wins = int(np.sum(np.all(both >= best, axis=1)))
    ratio = np.mean(
        [
            r["times"]["both inputs"]
            / (r["times"]["input 1 only"] + r["times"]["input 2 only"])
            for r in runs
        ]
    )
    print(f"seeds where every output's two-input fit >= its best one-input fit: "
          f"{wins}/{len(runs)}")  # fmt: skip
    print(f"two-input time / sum of the one-input times: {ratio:.2f} (goal <= 2)")


if __name__ == "__main__":
    main()
