"""Which physical element gives DaISy's arm the phase a hub-driven beam
lacks: the rig's modal form plus one element each, fitted to the record.

The rig's form (see ``benchmarks/daisy_greybox.py``): a hub torque reaches
the end acceleration, in modal coordinates, as ``a0 + sum_i a_i s^2 / (s^2
+ 2 z_i w_i s + w_i^2)``, one real residue per mode, over the arm's two
modes; its best fit whatever the rig's fields validates at 70.4 % against
ARX(8, 8, 0)'s 89.7 %. Each row multiplies that form by one element
``E(s)`` between the record's input and its output and fits it in the
cheapest way: residues and initial state by least squares, the modes'
frequencies and damping and the element's parameters by Levenberg-Marquardt
from the ARX's modes and a few element starts (the best by estimation fit
kept). ``datasets.robot_arm()`` (detrended; 0.01 s), estimated on the
first two thirds, validated on the last third after a warm-up over the
first two. Elements:

- ``input delay``: the held input delayed by ``tau`` (s), fractional, of
  either sign (negative: an advance), exact for the held input
  (:func:`spiralid.fms._zoh.discretise_delayed`);
- ``first-order hold``: the input linearly interpolated between samples
  (a measured, continuous torque rather than a held one), no parameter;
- ``first-order lag``: ``1 / (1 + s / wc)`` (a current loop's or a
  sensor's bandwidth);
- ``high-pass``: ``s / (s + wh)`` (an AC-coupled accelerometer);
- ``second-order sensor``: ``w^2 / (s^2 + 2 z w s + w^2)``;
- ``zero pair``: ``(s^2 + 2 z w s + w^2) / w^2`` on every mode (the hub's
  own dynamics between a reaction torque and the beam);
- ``lag and delay``: the first-order lag with an input delay.

``--shared-damping`` gives both modes one damping ratio (as the rig's
``damping_ratio`` does) rather than one each; ``--held-back`` fits on the
first three quarters of the estimation record and scores on its last
quarter (warm-up: the three quarters) in place of the validation third,
a choice made without seeing the validation third.

A free phase per mode (complex residues: non-proportional damping, or
anything else) is ARX(4, 5, 0), 89.6 % (``daisy_greybox.py``).

    python benchmarks/daisy_elements.py
"""

from __future__ import annotations

import argparse

import numpy as np
from scipy import signal
from scipy.optimize import least_squares

from spiralid.datasets import robot_arm
from spiralid.fms._zoh import delayed_inputs, discretise_delayed
from spiralid.sysid import ARX, identify

TAU = 2 * np.pi


def _response(num, den, u, ts: float, delay: float = 0.0, hold: str = "zoh"):
    """`u` through ``num(s) / den(s)`` sampled with its input held (`hold`
    "zoh", delayed by `delay` s) or linearly interpolated ("foh")."""
    a, b, c, d = signal.tf2ss(num, den)
    if hold == "foh":
        sys = signal.cont2discrete((a, b, c, d), ts, method="foh")
        return signal.dlsim((*sys[:4], ts), u)[1][:, 0]
    ad, g0, g1 = discretise_delayed(a, b[:, 0], ts, delay)
    whole = np.isclose(delay / ts, np.round(delay / ts), rtol=0, atol=1e-12)
    dd = np.hstack([d, 0 * d] if whole else [0 * d, d])
    bd = np.column_stack([g0, g1])
    return signal.dlsim((ad, bd, c, dd, ts), delayed_inputs(u, delay, ts))[1][:, 0]


def _element(kind: str, q):
    """``(num, den, real poles, delay, hold)`` of the element at `q`."""
    if kind == "none":
        return [1.0], [1.0], [], 0.0, "zoh"
    if kind == "input delay":
        return [1.0], [1.0], [], q[0], "zoh"
    if kind == "first-order hold":
        return [1.0], [1.0], [], 0.0, "foh"
    if kind in ("first-order lag", "lag and delay"):
        wc = np.exp(q[0])
        delay = q[1] if kind == "lag and delay" else 0.0
        return [wc], [1.0, wc], [-wc], delay, "zoh"
    if kind == "high-pass":
        wh = np.exp(q[0])
        return [1.0, 0.0], [1.0, wh], [-wh], 0.0, "zoh"
    w, z = np.exp(q[0]), q[1]
    if kind == "second-order sensor":
        z = abs(z)  # a sensor is stable: its damping's sign is not free
        return [w * w], [1.0, 2 * z * w, w * w], [], 0.0, "zoh"
    return [1 / w**2, 2 * z / w, 1.0], [1.0], [], 0.0, "zoh"  # zero pair


# Each element's starts: its parameters (log rad/s for a frequency, s for
# a delay, plain for a damping ratio).
STARTS = {
    "none": [[]],
    "input delay": [[d * 0.01] for d in (-0.8, -0.5, -0.2, 0.2, 0.5, 1.5)],
    "first-order hold": [[]],
    "first-order lag": [[np.log(TAU * f)] for f in (2, 5, 10, 20, 50)],
    "high-pass": [[np.log(TAU * f)] for f in (0.1, 0.5, 2, 5, 10)],
    "second-order sensor": [
        [np.log(TAU * f), z] for f in (8, 15, 25, 40) for z in (0.2, 0.7)
    ],
    "zero pair": [[np.log(TAU * f), z] for f in (3, 8, 15, 30) for z in (0.05, 0.5)],
    "lag and delay": [
        [np.log(TAU * f), d * 0.01] for f in (5, 20, 50) for d in (-0.5, 0.5)
    ],
}


def _columns(p, kind: str, u, ts: float, n_modes: int) -> np.ndarray:
    """The regressors at `p` (log Hz and log damping per mode, then the
    element's): the feedthrough and each mode through the element, each
    mode's two free responses and each real pole's of the element."""
    num, den, poles, delay, hold = _element(kind, p[2 * n_modes :])
    cols = [_response(num, den, u, ts, delay, hold)]
    for f, z in np.exp(np.reshape(p[: 2 * n_modes], (-1, 2))):
        w = TAU * f
        mode = [1.0, 2 * z * w, w * w]
        cols.append(
            _response(np.polymul([1, 0, 0], num), np.polymul(mode, den), u, ts,
                      delay, hold)
        )  # fmt: skip
        a = np.ravel(signal.cont2discrete(([1.0], mode), ts)[1])
        for k in range(2):
            cols.append(signal.lfilter([1.0], a, np.eye(1, u.size, k)[0]))
    for pole in poles:
        cols.append(np.exp(pole * ts) ** np.arange(u.size))
    return np.column_stack(cols)


def _expand(p, n_modes: int, shared: bool):
    """The per-mode parameters from `p`: with `shared`, ``p`` holds the
    modes' log frequencies, then one log damping for all, then the
    element's."""
    if not shared:
        return p
    modes = np.column_stack([p[:n_modes], np.full(n_modes, p[n_modes])])
    return np.r_[modes.ravel(), p[n_modes + 1 :]]


def _fit(kind, q0, est, val, modes, shared: bool = False):
    """Estimation and validation fit (%) and the parameters."""
    n_modes = modes.size // 2
    if shared:  # the log frequencies, then the modes' mean log damping
        pairs = np.reshape(modes, (-1, 2))
        modes = np.r_[pairs[:, 0], pairs[:, 1].mean()]

    def cols_of(p, u):
        return _columns(_expand(p, n_modes, shared), kind, u, est.ts, n_modes)

    def coef(p):
        cols = cols_of(p, est.u)
        return cols, np.linalg.lstsq(cols, est.y, rcond=None)[0]

    def residual(p):
        cols, c = coef(p)
        return est.y - cols @ c

    p = least_squares(residual, np.r_[modes, q0], diff_step=1e-6).x
    whole = cols_of(p, np.r_[est.u, val.u]) @ coef(p)[1]

    def pct(e, y):
        return 100 * (1 - np.linalg.norm(e) / np.linalg.norm(y - y.mean()))

    fits = pct(residual(p), est.y), pct(val.y - whole[est.n :], val.y)
    return (*fits, _expand(p, n_modes, shared))


def _describe(kind: str, p, n_modes: int) -> str:
    q = p[2 * n_modes :]
    modes = np.exp(np.reshape(p[: 2 * n_modes], (-1, 2)))
    text = ", ".join(f"{f:.3f} Hz ({z:.4f})" for f, z in modes)
    if kind in ("input delay",):
        text += f"; delay {1e3 * q[0]:.2f} ms"
    elif kind in ("first-order lag", "high-pass"):
        text += f"; corner {np.exp(q[0]) / TAU:.2f} Hz"
    elif kind == "lag and delay":
        text += f"; corner {np.exp(q[0]) / TAU:.2f} Hz, delay {1e3 * q[1]:.2f} ms"
    elif kind in ("second-order sensor", "zero pair"):
        text += f"; {np.exp(q[0]) / TAU:.2f} Hz, damping {q[1]:.3f}"
    return text


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", default=",".join(STARTS))
    ap.add_argument("--shared-damping", action="store_true")
    ap.add_argument("--held-back", action="store_true")
    args = ap.parse_args()
    data = robot_arm().detrend()
    est, val = data.split(2 / 3)
    if args.held_back:
        est, val = est.split(3 / 4)
    table = identify(est, ARX(8, 8, 0), method="oe", rng=0).modes
    keep = ~table.spurious
    modes = np.log(np.column_stack([table.frequency[keep], table.damping[keep]]))
    n_modes = int(keep.sum())
    print("| element | est. fit % | val. fit % |")
    print("|---|---|---|")
    found = {}
    for kind in args.elements.split(","):
        fits = []
        for q0 in STARTS[kind]:
            try:
                q0 = np.array(q0, float)
                shared = args.shared_damping
                fits.append(_fit(kind, q0, est, val, modes.ravel(), shared))
            except (ValueError, np.linalg.LinAlgError):
                continue  # a start whose run fails: the others decide
        best = max(fits, key=lambda r: r[0])
        found[kind] = best[2]
        print(f"| {kind} | {best[0]:.2f} | {best[1]:.2f} |", flush=True)
    print()
    for kind, p in found.items():
        print(f"{kind}: {_describe(kind, p, n_modes)}")


if __name__ == "__main__":
    main()
