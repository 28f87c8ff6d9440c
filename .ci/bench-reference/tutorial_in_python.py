#!/usr/bin/env python3
"""The tutorial's controller written in Python and run through `armscope.simulate`: its PD + gravity
feed-forward (u = kp∘(cmd − q) + kd∘(cmd_dot − q̇) + g(q), the motors' ±effort clipping armscope's)
called at every 1 kHz control step, on the tutorial's arm and wave, no files written, to time against
tutorial_loop.py (pydrake) as the whole process is timed:

    tutorial_in_python.py [--duration 30]     ->  the last pose, then `wall S loop S`
    tutorial_in_python.py --binding [ROUNDS]  ->  the binding's own cost per control step

`--binding` times the binding alone, in this one process, in turn: a controller that returns a ready
array (zero torque) through `armscope.simulate`, and `armscope.run` with zero gains and no feed-forward
(the same zero torque from Rust's own PD), each the best of ROUNDS; their difference per control step
is what calling Python costs the loop. Needs the armscope wheel installed
(pip install target/wheels/armscope-*.whl)."""
import argparse
import time

STARTED = time.perf_counter()

import warnings  # noqa: E402

import numpy as np  # noqa: E402

import armscope  # noqa: E402

args = argparse.ArgumentParser()
args.add_argument("--duration", type=float, default=30.0)
args.add_argument("--binding", type=int, nargs="?", const=7, metavar="ROUNDS")
a = args.parse_args()

reference = armscope.run(duration=0.001)  # the default experiment: its arm, gains and wave
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    model = armscope.Model(reference.summary["urdf"])
kp, kd = np.array(reference.summary["gains"]["kp"]), np.array(reference.summary["gains"]["kd"])
amplitude, omega = np.radians(30.0), 0.5
phases = np.arange(model.nq) * (np.pi / 3)
ready = np.zeros(model.nq)


def tutorial(t, q, qd):
    phase = omega * t + phases
    cmd, cmd_dot = amplitude * np.sin(phase), amplitude * omega * np.cos(phase)
    return kp * (cmd - q) + kd * (cmd_dot - qd) + model.gravity_torque(q)


def ready_array(t, q, qd):
    return ready


if a.binding:
    python, rust = [], []
    for _ in range(a.binding):
        started = time.perf_counter()
        armscope.simulate(model, ready_array, duration=a.duration, no_rrd=True, no_mcap=True)
        python.append(time.perf_counter() - started)
        started = time.perf_counter()
        armscope.run(duration=a.duration, kp="0", kd="0", no_ff=True, no_rrd=True, no_mcap=True)
        rust.append(time.perf_counter() - started)
    steps = round(a.duration / 0.001)
    print(f"a ready array through simulate: {1e3 * min(python):.1f} ms; run's own zero-gain PD: {1e3 * min(rust):.1f} ms "
          f"(best of {a.binding}); the binding: {1e6 * (min(python) - min(rust)) / steps:.2f} µs a control step")
    raise SystemExit

loop_started = time.perf_counter()
r = armscope.simulate(model, tutorial, duration=a.duration, no_rrd=True, no_mcap=True)
loop = time.perf_counter() - loop_started
print("final q (rad):", " ".join(f"{x:.4f}" for x in r.q[-1]), f"({len(r.t)} steps)")
print(f"wall {time.perf_counter() - STARTED:.3f} loop {loop:.3f}")
