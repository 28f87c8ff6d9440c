#!/usr/bin/env bash
# Remake every picture of the user guide (docs/src/images/) from the commands its captions give.
#   bash docs/figures.sh [ARMSCOPE]
# Needs: the armscope binary (default target/release/armscope), a viewer kit that screenshots an .rrd in
# the Rerun viewer and an .mcap in Foxglove Studio (VIEWERS: a folder with rrd2png.sh and mcap2png.sh),
# and example-robot-data's robots folder (ROBOTS; `pip install example-robot-data`) for the SO-100 and Panda.
set -euo pipefail
cd "$(dirname "$0")/.."
repo="$PWD"
armscope="$(realpath "${1:-target/release/armscope}")"
viewers="$(realpath "${VIEWERS:-../shared/viewers}")"
robots="${ROBOTS:?set ROBOTS to the robots folder of example-robot-data}"
images="$repo/docs/src/images"
work="$(mktemp -d)"
cd "$work"
rrd() { MODE=x11 bash "$viewers/rrd2png.sh" "$1" "$images/$2"; }
fox() { LAYOUT="${1%.mcap}.layout.json" bash "$viewers/mcap2png.sh" "$1" "$images/$2"; }
A() { "$armscope" "$@" > /dev/null 2>&1 || { echo "figures: armscope $* failed" >&2; "$armscope" "$@" >&2; exit 1; }; }
A0() { "$armscope" "$@" > /dev/null 2>&1 || [ $? -eq 4 ]; }   # exit 4: stopped at the first contact, as asked

# the tutorial's default run and --no-ff (run.md, recordings.md, README)
A run --name default
A run --no-ff --name no-ff
rrd recordings/default.rrd rerun_default.png
rrd recordings/no-ff.rrd rerun_no-ff.png
fox recordings/default.mcap foxglove_default.png
A compare recordings/default.mcap recordings/no-ff.mcap
rrd recordings/comparison.rrd comparison_default_vs_no-ff.png
# the tutorial's batch, compared (batch.md)
A batch
rrd recordings/tutorial/comparison.rrd comparison_tutorial.png
# the SO-100, torque plots scaled to the motion (recordings.md)
A run --urdf "$robots/so_arm_description/urdf/so100.urdf" --duration 10 --name so100
rrd recordings/so100.rrd rerun_so100.png
fox recordings/so100.mcap foxglove_so100.png
# the same file with the geometry hidden: Foxglove draws the arm from /robot_description
python3 - recordings/so100.layout.json recordings/so100_urdf.layout.json <<'PY'
import json, sys
layout = json.load(open(sys.argv[1]))
for key, panel in layout["configById"].items():
    if key.startswith("3D!"):
        panel["topics"]["/robot/geometry"] = {"visible": False}
        panel["topics"]["/robot_description"] = {"visible": True}
json.dump(layout, open(sys.argv[2], "w"))
PY
LAYOUT=recordings/so100_urdf.layout.json bash "$viewers/mcap2png.sh" recordings/so100.mcap "$images/foxglove_urdf.png"
# the mesh model (run.md) and the circle drawn with the tool
A run --urdf "$repo/assets/smallrobotarm/smallrobotarm.urdf" --duration 6 --name mesh
rrd recordings/mesh.rrd rerun_mesh.png
fox recordings/mesh.mcap foxglove_mesh.png
A trajectory circle
A run --trajectory recordings/trajectory_circle.csv --duration 10 --dt 0.0001 --name circle
rrd recordings/circle.rrd rerun_circle.png
# the Panda (your-arm.md)
A run --urdf "$robots/panda_description/urdf/panda.urdf" --duration 10 --name panda
rrd recordings/panda.rrd rerun_panda.png
fox recordings/panda.mcap foxglove_panda.png
# stepper mode with the real arm's reductions (motors.md)
A run --motors "$repo/assets/motors/smallrobotarm.toml" --duration 10 --name stepper
rrd recordings/stepper.rrd rerun_stepper.png
fox recordings/stepper.mcap foxglove_stepper.png
# collisions: the Panda folding onto itself, the box model meeting a table (collisions.md)
A run --urdf "$robots/panda_description/urdf/panda.urdf" --trajectory "$repo/assets/experiments/panda_fold.csv" --collisions --duration 2.1 --name panda_fold
rrd recordings/panda_fold.rrd rerun_panda_fold.png
A0 run --scene "$repo/assets/scenes/box_model_table.toml" --stop-on-collision --name box_table
fox recordings/box_table.mcap foxglove_box_table.png
# charts armscope draws itself (stability.md, sizing.md, tour.md)
A envelope
cp recordings/envelope/envelope_J1.png "$images/envelope_J1.png"
A size --freq 1.2 --payload 0.5 --out recordings/size_catalogue
cp recordings/size_catalogue/size_J2.png "$images/size_catalogue_J2.png"
A size --freq 1.2 --payload 0.5 --ratios 1-50 --efficiency 0.9 --candidates 17HS4401,17HS19-2004S1,23HS22-2804S --out recordings/size_ideal
cp recordings/size_ideal/size_J2.png "$images/size_J2.png"
A size --urdf "$repo/tests/fixtures/robots/so101.urdf" --payload 0.2 --parts-in-urdf --candidates STS3215-C018,STS3215-C001,XM430-W350 --out recordings/size_so101
cp recordings/size_so101/size_shoulder_lift.png "$images/size_so101_shoulder_lift.png"
# a ROS 2 recording in Rerun's MCAP importer (recordings.md)
A run --mcap-encoding ros2 --mcap recordings/run_ros2.mcap --no-rrd
MODE=rerun bash "$viewers/mcap2png.sh" recordings/run_ros2.mcap "$images/rerun_ros2_import.png"
# the test bag replayed with the SO-101's servos and 0.2 kg (replay.md)
A replay "$repo/tests/fixtures/ros2/joint_states_effort.mcap" --urdf "$repo/tests/fixtures/robots/so101.urdf" --motors "$repo/assets/motors/so101.toml" --payload 0.2 --rrd recordings/replay.rrd --no-mcap
rrd recordings/replay.rrd rerun_replay_so101.png
echo "figures: remade in $images (work folder $work)"
