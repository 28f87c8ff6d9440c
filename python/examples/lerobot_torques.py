"""A LeRobot dataset's needed torques in a pandas DataFrame: each episode of a real SO-101 replayed
(the arm's inverse dynamics along its smoothed motion), the peak and RMS torque per joint, and the
servo's peak duty, one row per episode and joint.

    python lerobot_torques.py DATASET so101.urdf [MOTORS.toml]
"""
import sys
import warnings

import pandas as pd

import armscope

dataset, urdf = sys.argv[1], sys.argv[2]
motors = sys.argv[3] if len(sys.argv) > 3 else None
with warnings.catch_warnings():
    warnings.simplefilter("ignore")  # what the reading assumed (the unit, the ranges), said as warnings
    episodes = armscope.replay(dataset, urdf, motors=motors)
rows = []
for ep in episodes:
    for v in ep.verdicts:
        rows.append({
            "episode": ep.episode,
            "joint": v["joint"],
            "peak N·m": v["peak_torque"],
            "rms N·m": v["rms_torque"],
            "s over limit": v["time_over"],
            "peak duty": v["servo"]["peak_duty"] if v.get("servo") else None,
        })
table = pd.DataFrame(rows)
print(table.pivot(index="joint", columns="episode", values="peak N·m").round(3))
print(table.groupby("joint")[["rms N·m", "peak duty"]].max().round(3))
