#!/usr/bin/env python3
"""The pydrake tutorial's experiment, as ../shared/reference/README.md describes it, to time it on the
same machine as armscope: Drake's discrete MultibodyPlant (h = 1 ms) of the URDF, and a Python loop at
1 kHz that reads the state, computes u = kp∘(cmd − q) + kd∘(cmd_dot − q̇) − τ_g(q) clipped to ±effort
for the wave cmd_i = A·sin(ω t + i·π/3), holds it over the step and advances the simulator; the state
is recorded every 0.5 s (the tutorial's CSV: t, q, tool xyz) and summarized at the end (max error over
those samples with t ≥ 2 s, saturation %, tool range).

    tutorial_loop.py URDF [--duration 30] [--csv OUT.csv]   ->  the summary, then `wall S loop S`

`wall` is the whole process (Python, pydrake's import, the model, the loop), as `armscope run` is timed;
`loop` the control loop alone. Not the tutorial's own file (the repository does not have it): its loop
rebuilt from the reference's description. Its states stay within 2e-9 rad of Drake's own record of the
run (../shared/reference/steps/default_10s_clean.csv.gz) over those 10 s, and its summary is
armscope's. pip install drake==1.51.1 numpy (PyPI's wheel)."""
import argparse
import math
import time

STARTED = time.perf_counter()

import numpy as np  # noqa: E402
from pydrake.multibody.parsing import Parser  # noqa: E402
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, DiscreteContactApproximation  # noqa: E402
from pydrake.systems.analysis import Simulator  # noqa: E402
from pydrake.systems.framework import DiagramBuilder  # noqa: E402

KP = np.array([200.0, 300.0, 200.0, 120.0, 80.0, 30.0])
KD = np.array([12.0, 10.0, 4.5, 1.3, 0.4, 0.1])

args = argparse.ArgumentParser()
args.add_argument("urdf")
args.add_argument("--duration", type=float, default=30.0)
args.add_argument("--freq", type=float, default=0.5)
args.add_argument("--amp-deg", type=float, default=30.0)
args.add_argument("--csv")
a = args.parse_args()

dt = 0.001
builder = DiagramBuilder()
plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=dt)
# as the reference records were made (SAP, lagged): Drake's discrete update of the reference README
plant.set_discrete_contact_approximation(DiscreteContactApproximation.kLagged)
Parser(plant).AddModels(a.urdf)
plant.Finalize()
diagram = builder.Build()
simulator = Simulator(diagram)
context = simulator.get_mutable_context()
plant_context = plant.GetMyMutableContextFromRoot(context)
# the URDF's efforts, joint by joint in the plant's order (the box model has no <transmission>, so
# Drake made no actuators: the torque goes in as an applied generalized force, as the tutorial's)
import xml.etree.ElementTree as ET  # noqa: E402
limits = {j.get("name"): float(j.find("limit").get("effort")) for j in ET.parse(a.urdf).getroot().iter("joint") if j.find("limit") is not None}
effort = np.array([limits[plant.get_joint(i).name()] for i in plant.GetJointIndices() if plant.get_joint(i).num_velocities() == 1])
tool = plant.GetBodyByName("tool_link").body_frame()
world = plant.world_frame()
actuation = plant.get_applied_generalized_force_input_port()
n = plant.num_positions()
amp = math.radians(a.amp_deg)
phase = np.arange(n) * math.pi / 3

rows, errors, saturated, steps = [], [], np.zeros(n), 0
loop_started = time.perf_counter()
t = 0.0
for k in range(int(round(a.duration / dt)) + 1):
    t = k * dt
    q = plant.GetPositions(plant_context)
    v = plant.GetVelocities(plant_context)
    cmd = amp * np.sin(a.freq * t + phase)
    cmd_dot = amp * a.freq * np.cos(a.freq * t + phase)
    tau_g = plant.CalcGravityGeneralizedForces(plant_context)
    u = KP * (cmd - q) + KD * (cmd_dot - v) - tau_g
    saturated += np.abs(u) > effort
    steps += 1
    u = np.clip(u, -effort, effort)
    if k % 500 == 0:
        tip = plant.CalcPointsPositions(plant_context, tool, [0.0, 0.0, 0.0], world)[:, 0]
        rows.append([t, *q, *tip])
        if t >= 2.0:
            errors.append(np.abs(cmd - q))
    if k == int(round(a.duration / dt)):
        break
    actuation.FixValue(plant_context, u)
    # to (k + 1)·dt, not t + dt: a sum drifts off Drake's update times and a step takes 0 or 2 updates
    simulator.AdvanceTo((k + 1) * dt)
loop = time.perf_counter() - loop_started

rows = np.array(rows)
print("max |error| (rad, every 0.5 s, t >= 2 s):", " ".join(f"{e:.3f}" for e in np.max(errors, axis=0)))
print("saturation (%):", " ".join(f"{100 * s / steps:.0f}" for s in saturated))
print("tool range:", " ".join(f"{c}[{rows[:, 1 + n + i].min():.3f}, {rows[:, 1 + n + i].max():.3f}]" for i, c in enumerate("xyz")))
if a.csv:
    header = ",".join(["t"] + [f"q{i + 1}" for i in range(n)] + ["x", "y", "z"])
    np.savetxt(a.csv, rows, delimiter=",", header=header, comments="", fmt="%.9g")
print(f"wall {time.perf_counter() - STARTED:.3f} loop {loop:.3f}")
