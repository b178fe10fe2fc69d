"""The two-mode, two-sensor system the several-output tests share: modes at
3 Hz (damping 0.03) and 11 Hz (0.05), sampled by zero-order hold, and a
numerator per sensor."""

import numpy as np
from scipy import signal

from spiralid.sysid import IOData

TS = 0.01
MODES = ((3.0, 0.03), (11.0, 0.05))


def _denominator() -> np.ndarray:
    poles = []
    for f, zeta in MODES:
        wn = 2 * np.pi * f
        s = -zeta * wn + 1j * wn * np.sqrt(1 - zeta**2)
        poles += [np.exp(s * TS), np.exp(np.conj(s) * TS)]
    return np.poly(poles).real


A = _denominator()
# Sensor 2 sits near a node of the 11 Hz mode: its numerator nearly cancels
# that pole pair in its own response (the zeros put on it).
B = np.array([[0.0, 0.02, 0.015, -0.01, 0.004], [0.0, 0.01, 0.0, 0.0, 0.0]])


def record(seed=0, n=1500, noise=(0.002, 0.002)) -> IOData:
    """White-noise input of `n` samples and both sensors' outputs with white
    measurement noise of the given standard deviations."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = np.column_stack([signal.lfilter(b, A, u) for b in B])
    y += rng.standard_normal(y.shape) * np.array(noise)
    return IOData(u, y, ts=TS, output_name=("near", "far"), output_unit=("m", "m"))
