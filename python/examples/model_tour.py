"""armscope.Model in a few lines: an SO-101's gravity torques, the torque a motion needs, and where
its gripper goes — one state, then a whole trajectory at once.

    python model_tour.py so101.urdf
"""
import sys
import warnings

import numpy as np

import armscope

with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # the URDF's missing meshes, said as warnings
    m = armscope.Model(sys.argv[1] if len(sys.argv) > 1 else "so101.urdf")
print(m.nq, "joints:", ", ".join(m.joint_names))

# the torque that holds the arm still, stretched out
q = np.zeros(m.nq)
print("holding torque (N·m):", np.round(m.gravity_torque(q), 3))

# a 2 s swing of the shoulder and elbow sampled at 1 kHz: the torque every state needs, in one call
t = np.linspace(0.0, 2.0, 2001)
Q = np.zeros((t.size, m.nq))
Q[:, 1] = 0.8 * np.sin(np.pi * t)
Q[:, 2] = -0.6 * np.sin(np.pi * t)
V = np.gradient(Q, t, axis=0)
A = np.gradient(V, t, axis=0)
tau = m.rnea(Q, V, A)
print("peak torque per joint (N·m):", np.round(np.abs(tau).max(axis=0), 3))

# where the gripper goes, and how fast
poses = m.frame_pose(Q, "gripper_link")
speed = np.einsum("nij,nj->ni", m.jacobian(Q, "gripper_link")[:, :3], V)
print("gripper at rest", np.round(poses[0, :3, 3], 3), "m, at 0.5 s", np.round(poses[500, :3, 3], 3), "m; top speed",
      round(float(np.linalg.norm(speed, axis=1).max()), 3), "m/s")
