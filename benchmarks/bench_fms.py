"""Speed of the flexible manipulator simulator (prints figures, asserts nothing).

Run: ``.venv/bin/python benchmarks/bench_fms.py``.  Build = constructing the
default rig and solving its modes; simulate = 10 s of bang-bang torque with the
default sensors, first call (includes the exact ZOH discretisation, cached per
rig and sample rate) and a repeat call.
"""

import time

import numpy as np

from spiralid.fms import FlexibleManipulator, Sensors, bang_bang


def _best(fn, repeat=5):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    noisy = Sensors(accel_noise=1.0, tach_noise=0.01)
    for ne in (10, 20):
        t0 = time.perf_counter()
        rig = FlexibleManipulator(n_elements=ne)
        f = rig.modes()
        build = time.perf_counter() - t0
        print(f"n_elements={ne}: build + modes {build * 1e3:.2f} ms")
        print("  first five modes (Hz):", np.array2string(f[:5], precision=3))
        for fs in (500.0, 5000.0):
            u = bang_bang(0.3, 0.04, 0.1, 10.0, fs)
            fresh = FlexibleManipulator(n_elements=ne)
            t0 = time.perf_counter()
            fresh.simulate(u, fs=fs, rng=0)
            first = time.perf_counter() - t0
            warm = _best(lambda rig=fresh, u=u, fs=fs: rig.simulate(u, fs=fs, rng=0))
            warm_noise = _best(
                lambda rig=fresh, u=u, fs=fs: rig.simulate(
                    u, fs=fs, rng=0, sensors=noisy
                )
            )
            print(
                f"  simulate 10 s at {fs:6.0f} Hz ({u.size:5d} samples): "
                f"first {first * 1e3:7.2f} ms, repeat {warm * 1e3:7.2f} ms, "
                f"repeat with noise {warm_noise * 1e3:7.2f} ms"
            )


if __name__ == "__main__":
    main()
