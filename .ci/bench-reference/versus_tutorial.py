#!/usr/bin/env python3
"""armscope's default run against the tutorial's loop (tutorial_loop.py), on the same machine in turn:
    versus_tutorial.py ARMSCOPE DRAKE_PYTHON [ROUNDS] [ARMSCOPE_PYTHON]
Each round runs the tutorial once, then `ARMSCOPE run` (with both recordings, and without them) three
times each, and, given a Python with the armscope wheel installed, the tutorial's controller written in
Python through `armscope.simulate` (tutorial_in_python.py, no files) three times, in a scratch folder.
Prints each one's median wall time (whole processes) and the ratios. This machine's speed drifts by tens of percent
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
rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 7
urdf = os.path.join(here, "..", "..", "assets", "smallrobot_arm.urdf")
cases = {"both files": [armscope, "run"], "no files": [armscope, "run", "--no-rrd", "--no-mcap"]}
if len(sys.argv) > 4:
    cases["python controller"] = [os.path.abspath(sys.argv[4]) if os.sep in sys.argv[4] else sys.argv[4], os.path.join(here, "tutorial_in_python.py")]


def wall(command, cwd):
    started = time.perf_counter()
    subprocess.run(command, cwd=cwd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - started


times = {"tutorial": [], **{name: [] for name in cases}}
with tempfile.TemporaryDirectory() as scratch:
    for name, command in cases.items():  # warm: the files exist, as when a run is repeated
        wall(command, scratch)
    for _ in range(rounds):
        times["tutorial"].append(wall([python, os.path.join(here, "tutorial_loop.py"), urdf], scratch))
        for name, command in cases.items():
            for _ in range(3):
                times[name].append(wall(command, scratch))
median = {name: statistics.median(t) for name, t in times.items()}
for name, t in times.items():
    print(f"{name:>17}: median {median[name] * 1e3:8.1f} ms  (min {min(t) * 1e3:.1f}, max {max(t) * 1e3:.1f}, n = {len(t)})")
for name in cases:
    print(f"the tutorial / armscope with {name}: {median['tutorial'] / median[name]:.1f}x")
