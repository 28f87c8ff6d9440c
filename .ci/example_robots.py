"""Where the PyPI package example-robot-data (a cmeel package) keeps its robots, for the CI checks."""
import os
import sys


def robots_dir():
    import cmeel  # noqa: F401  (example-robot-data is a cmeel package)
    for p in sys.path:
        d = os.path.join(p, "cmeel.prefix", "share", "example-robot-data", "robots")
        if os.path.isdir(d):
            return d
    sys.exit("example-robot-data not found")


# The fixed-base robots of example-robot-data the CI checks hold armscope against, by name: each URDF
# under robots_dir().
ROBOTS = {
    "ur3": "ur_description/urdf/ur3_robot.urdf",
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "ur10": "ur_description/urdf/ur10_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
    "kinova": "kinova_description/robots/kinova.urdf",
    "so100": "so_arm_description/urdf/so100.urdf",
    "so101": "so_arm_description/urdf/so101.urdf",
    "xarm7": "xarm_description/urdf/xarm7.urdf",
    "z1": "z1_description/urdf/z1.urdf",
    "double_pendulum": "double_pendulum_description/urdf/double_pendulum.urdf",
    "asr_twodof": "asr_twodof_description/urdf/TwoDofs.urdf",
    "finger_edu": "finger_edu_description/robots/finger_edu.urdf",
    "talos_left_arm": "talos_data/robots/talos_left_arm.urdf",
    "baxter": "baxter_description/urdf/baxter.urdf",
    "allegro": "allegro_hand_description/urdf/allegro_right_hand.urdf",
    "tiago": "tiago_description/robots/tiago.urdf",
    "pr2": "pr2_description/urdf/pr2.urdf",
}
