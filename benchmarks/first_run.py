"""The first `spiralid reproduce` after an install, and the next (prints only).

Run: ``.venv/bin/python benchmarks/first_run.py`` (two runs of the command at
its defaults; docs/results/reproduction.md gives measured times).

1. The command, cold then warm. Cold: an empty ``NUMBA_CACHE_DIR``, so every
   kernel compiles as on a fresh install; warm: the same directory again,
   so every kernel loads. Each run writes into a fresh output folder. Wall
   time, CPU time (the command and its workers) and the load average
   before each run; the compile share is what the cold run took beyond the
   warm one.
2. One process's compilation: a fresh interpreter runs the warm-up every
   worker runs (``reproduction._warm_up``, one tiny search per method and
   parametrisation), cold and warm, with Numba's compile events timed. The
   workers compile side by side, so on 2 cores this is about what the cold
   run adds to the wall time.

``--args`` passes options to the command (``--args "--seeds 2"``);
``--repeat N`` measures N cold/warm pairs.
"""

import argparse
import json
import os
import resource
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SCRIPT = Path(sys.executable).parent / "spiralid"

# One worker's warm-up, with the outermost compilations timed (a kernel
# that calls another compiles it inside its own compilation).
_WARM_UP = """
import json, time
from numba.core import event

class Compiles(event.Listener):
    depth, start, total = 0, 0.0, 0.0
    def on_start(self, ev):
        if self.depth == 0:
            self.start = time.perf_counter()
        self.depth += 1
    def on_end(self, ev):
        self.depth -= 1
        if self.depth == 0:
            self.total += time.perf_counter() - self.start

compiles = Compiles()
event.register("numba:compile", compiles)
t0 = time.perf_counter()
from spiralid import reproduction
from spiralid.sysid import ARX
imported = time.perf_counter() - t0
est, _ = reproduction.default_data().split(2 / 3)
kinds = sorted({(c.method, c.parametrization) for c in reproduction.CONFIGURATIONS})
t1 = time.perf_counter()
reproduction._warm_up(est, ARX(8, 8, 0), kinds, "rest")
print(json.dumps({"import": imported, "warm_up": time.perf_counter() - t1,
                  "compile": compiles.total}))
"""


def _children_cpu() -> float:
    use = resource.getrusage(resource.RUSAGE_CHILDREN)
    return use.ru_utime + use.ru_stime


def _reproduce(cache: str, out: Path, args: list[str]) -> tuple[float, float, float]:
    """Wall and CPU seconds of one run, and the 1-minute load before it."""
    env = {**os.environ, "NUMBA_CACHE_DIR": cache, "MPLBACKEND": "Agg"}
    load = os.getloadavg()[0]
    cpu, t0 = _children_cpu(), time.perf_counter()
    subprocess.run(
        [str(SCRIPT), "reproduce", "--out", str(out), "--quiet", *args],
        env=env,
        check=True,
    )
    return time.perf_counter() - t0, _children_cpu() - cpu, load


def _warm_up(cache: str) -> dict:
    # As in the workers: one BLAS thread (study.runner._single_threaded_blas).
    env = {**os.environ, "NUMBA_CACHE_DIR": cache, "OPENBLAS_NUM_THREADS": "1"}
    out = subprocess.run(
        [sys.executable, "-c", _WARM_UP],
        env=env,
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--args", default="", help="options for the command")
    parser.add_argument("--repeat", type=int, default=1, help="cold/warm pairs")
    opts = parser.parse_args()
    args = shlex.split(opts.args)
    print(f"{os.cpu_count()} cores; spiralid reproduce {' '.join(args)}".rstrip())
    for _ in range(opts.repeat):
        with tempfile.TemporaryDirectory() as tmp:
            cache = str(Path(tmp) / "numba")
            cold = _reproduce(cache, Path(tmp) / "cold", args)
            warm = _reproduce(cache, Path(tmp) / "warm", args)
        for label, (wall, cpu, load) in (("first run (cold)", cold), ("warm", warm)):
            print(f"{label:17s} {wall:6.1f} s wall {cpu:6.1f} s CPU  (load {load:.1f})")
        share = (cold[0] - warm[0]) / cold[0]
        print(f"compile share    {cold[0] - warm[0]:6.1f} s wall ({share:.0%})")
    with tempfile.TemporaryDirectory() as tmp:
        cache = str(Path(tmp) / "numba")
        load = os.getloadavg()[0]
        cold, warm = _warm_up(cache), _warm_up(cache)
    print(
        f"one worker's warm-up (load {load:.1f}): import {cold['import']:.1f} s; "
        f"cold {cold['warm_up']:.1f} s, of which compiling {cold['compile']:.1f} s; "
        f"warm {warm['warm_up']:.1f} s, compiling {warm['compile']:.1f} s"
    )


if __name__ == "__main__":
    main()
