#!/usr/bin/env python3
"""armscope's default run against the tutorial's loop (tutorial_loop.py), on the same machine in turn:
    versus_tutorial.py ARMSCOPE DRAKE_PYTHON [ROUNDS] [-- armscope run flags]
Each round runs the tutorial once, then `ARMSCOPE run` (by default with both recordings, as the
speed issue measures it, and without them) three times each, in a scratch folder. Prints each one's
median wall time (whole processes) and the ratios. This machine's speed drifts by tens of percent
within minutes: only the ratios of interleaved medians mean anything."""
import os
import statistics
import subprocess
import sys
import tempfile
import time

here = os.path.dirname(os.path.abspath(__file__))
# the runs happen in a scratch folder: a relative path (target/release/armscope) is made absolute
armscope, python = (os.path.abspath(a) if os.sep in a else a for a in sys.argv[1:3])
rounds = int(sys.argv[3]) if len(sys.argv) > 3 and sys.argv[3] != "--" else 7
urdf = os.path.join(here, "..", "..", "assets", "smallrobot_arm.urdf")
cases = {"both files": [], "no files": ["--no-rrd", "--no-mcap"]}


def wall(command, cwd):
    started = time.perf_counter()
    subprocess.run(command, cwd=cwd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - started


times = {"tutorial": [], **{name: [] for name in cases}}
with tempfile.TemporaryDirectory() as scratch:
    for name, flags in cases.items():  # warm: the files exist, as when a run is repeated
        wall([armscope, "run", *flags], scratch)
    for _ in range(rounds):
        times["tutorial"].append(wall([python, os.path.join(here, "tutorial_loop.py"), urdf], scratch))
        for name, flags in cases.items():
            for _ in range(3):
                times[name].append(wall([armscope, "run", *flags], scratch))
median = {name: statistics.median(t) for name, t in times.items()}
for name, t in times.items():
    print(f"{name:>10}: median {median[name] * 1e3:8.1f} ms  (min {min(t) * 1e3:.1f}, max {max(t) * 1e3:.1f}, n = {len(t)})")
for name in cases:
    print(f"the tutorial / armscope run with {name}: {median['tutorial'] / median[name]:.1f}x")
