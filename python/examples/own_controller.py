"""Your own controller in the loop: the tutorial's PD + gravity feed-forward written in Python, against
a computed-torque controller (M(q)·(q̈_d + kp·e + kd·ė) + bias), on the tutorial's arm and wave; the
tracking error of each, and both runs recorded for Rerun.

    python own_controller.py [OUT_FOLDER]
"""
import os
import sys
import warnings

import numpy as np

import armscope

out = sys.argv[1] if len(sys.argv) > 1 else "."
reference = armscope.run(duration=0.01)  # the default experiment: its model, gains and wave
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    m = armscope.Model(reference.summary["urdf"])
kp, kd = np.array(reference.summary["gains"]["kp"]), np.array(reference.summary["gains"]["kd"])
amplitude, omega = np.radians(30.0), 0.5
phases = np.arange(m.nq) * (np.pi / 3)


def wave(t):
    phase = omega * t + phases
    return amplitude * np.sin(phase), amplitude * omega * np.cos(phase), -amplitude * omega**2 * np.sin(phase)


def tutorial(t, q, qd):
    cmd, cmd_dot, _ = wave(t)
    return kp * (cmd - q) + kd * (cmd_dot - qd) + m.gravity_torque(q)


def computed_torque(t, q, qd):
    # the arm's rigid-body dynamics cancelled, each joint a critically damped 10 rad/s loop; the
    # URDF's joint damping is the plant's, not the model's: on the light wrist joints it is left
    # uncancelled, and they lag
    cmd, cmd_dot, cmd_ddot = wave(t)
    wn = 10.0
    a = cmd_ddot + wn * wn * (cmd - q) + 2 * wn * (cmd_dot - qd)
    return m.rnea(q, qd, a)


for name, controller in [("tutorial", tutorial), ("computed_torque", computed_torque)]:
    r = armscope.simulate(m, controller, duration=10, rrd=os.path.join(out, f"{name}.rrd"), no_mcap=True)
    error = np.abs(r.q - r.q_target)[r.t > 2.0].max(axis=0)
    print(f"{name:16s} largest tracking error after 2 s (mrad):", np.round(1e3 * error, 3), "saturated steps:", int(r.saturated.any(axis=1).sum()))
