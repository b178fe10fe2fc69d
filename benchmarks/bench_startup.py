"""Start-up cost: imports and a small `spiralid identify` (prints, asserts nothing).

Run: ``.venv/bin/python benchmarks/bench_startup.py``. Each figure is the
median of 5 fresh interpreters; `identify` is the console script on the
shipped robot arm with least squares (computation about 0.1 s), so its wall
time is start-up, validation and figure drawing.
"""

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SCRIPT = Path(sys.executable).parent / "spiralid"


def _import(module: str) -> float:
    code = f"import time; t = time.perf_counter(); import {module}; "
    code += "print(time.perf_counter() - t)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    return float(out.stdout)


def _identify() -> float:
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        subprocess.run(
            [str(SCRIPT), "identify", "robot_arm", "--method", "ls", "--quiet"],
            cwd=tmp,
            check=True,
            env={**os.environ, "MPLBACKEND": "Agg"},
        )
        return time.perf_counter() - t0


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    for label, fn in (
        ("import numpy", lambda: _import("numpy")),
        ("import spiralid", lambda: _import("spiralid")),
        ("import spiralid.sysid", lambda: _import("spiralid.sysid")),
        ("spiralid identify robot_arm --method ls", _identify),
    ):
        print(f"{label:42s} {statistics.median(fn() for _ in range(5)):7.3f} s")


if __name__ == "__main__":
    main()
