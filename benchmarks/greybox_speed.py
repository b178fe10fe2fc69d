"""A nonlinear grey box's simulation in Python against the same functions
compiled by Numba.

The Cascaded Tanks model (:mod:`spiralid.datasets.tanks_model`, 2 states,
1,024 samples, 4 Runge-Kutta sub-steps: 16,384 calls of ``f`` per
simulation) is simulated with its Numba ``f`` and ``g`` (the compiled loop)
and with their Python originals (the interpreted loop; the default
overflow's ``f`` is a Numba call of the shared body ``_rates``, so its
original is that body's ``py_func``, every call interpreted); the script
prints the milliseconds per simulation (median of ``--repeat``), the
ratio, the largest difference between the two outputs, and the one-off
compile time. Seconds on a loaded machine are indicative.

    python benchmarks/greybox_speed.py --repeat 20
"""

import argparse
import time

import numpy as np

from spiralid.datasets import cascaded_tanks, tanks_model
from spiralid.datasets.tanks_model import tanks_g, tanks_greybox
from spiralid.sysid import GreyBox


def per_simulation(
    box: GreyBox, values, u, ts, repeat: int
) -> tuple[float, np.ndarray]:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        y = box.simulate(values, u, ts)
        times.append(time.perf_counter() - start)
    return float(np.median(times)), y


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=10)
    args = parser.parse_args()
    est = cascaded_tanks()
    compiled = tanks_greybox()
    python = GreyBox(
        compiled.parameters,
        f=lambda t, x, u, p: tanks_model._rates.py_func(x, u, p, True),
        g=tanks_g.py_func,
        n_states=2,
        x0=list(compiled.state_parameters),
        substeps=compiled.substeps,
    )
    values = compiled.initial_values
    start = time.perf_counter()
    compiled.simulate(values, est.u, est.ts)
    first = time.perf_counter() - start
    t_nb, y_nb = per_simulation(compiled, values, est.u, est.ts, args.repeat)
    t_py, y_py = per_simulation(python, values, est.u, est.ts, max(args.repeat // 5, 1))
    print(f"first compiled call (compiles): {first:.2f} s")
    print(f"Numba  : {1e3 * t_nb:8.2f} ms per simulation")
    print(f"Python : {1e3 * t_py:8.2f} ms per simulation")
    print(f"Python / Numba: {t_py / t_nb:.0f}x")
    print(f"largest |y_python - y_numba|: {np.max(np.abs(y_py - y_nb)):.2e} V")


if __name__ == "__main__":
    main()
