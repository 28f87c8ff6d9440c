#!/usr/bin/env python3
"""`armscope replay` against Pinocchio 4.1 on LeRobot datasets written here by pyarrow as LeRobot
writes them (v3.0: three episodes in one data file, a row group each, an episodes table; v2.1: one file
per episode, episodes.jsonl), of known SO-101 motions (example-robot-data's so101.urdf) at 30 fps,
quantized to the encoder (360/4095° in DEGREES with per-joint signs and offsets, the gripper 0..100).
Per joint, the needed torque of `--trace` is within 2 % of that joint's peak + 5 mN·m of Pinocchio's
rnea of the true motion (0.5 s from either end left out), with and without 0.2 kg at the tool; the
intervals where shoulder_lift needs more than 2.9 N·m with the payload match to one frame. Run by
.ci/run with the corpus venv (pin, example-robot-data, pyarrow)."""
import glob, json, math, os, subprocess, sys, tempfile
import numpy as np
import pinocchio as pin
import pyarrow as pa
import pyarrow.parquet as pq

armscope = sys.argv[1]
robots = glob.glob(sys.prefix + "/lib/python3*/site-packages/cmeel.prefix/share/example-robot-data/robots")[0]
URDF = os.path.join(robots, "so_arm_description/urdf/so101.urdf")
NAMES = ["shoulder_pan", "shoulder_lift", "elbow_flex", "wrist_flex", "wrist_roll", "gripper"]
COLUMNS = [n + ".pos" for n in NAMES]
SIGNS = [1, -1, 1, -1, 1]
OFFSETS = [0.05, -0.12, 0.3, 0.0, -0.2]
FPS, SECONDS, TOOL = 30, 20, "gripper_frame_link"
BASE = [  # per joint: center, [(amplitude, rad/s, phase)]
    (0.1, [(0.9, 1.1, 0.0), (0.25, 2.7, 1.0)]),
    (0.3, [(0.9, 1.6, 0.3), (0.4, 8.5, 0.0)]),
    (-0.3, [(0.8, 1.7, 2.0), (0.2, 3.7, 0.0)]),
    (0.0, [(0.5, 2.1, 0.5), (0.2, 4.3, 0.0)]),
    (0.0, [(1.2, 0.9, 0.0), (0.3, 2.3, 1.0)]),
    (0.8, [(0.6, 1.9, 0.0)]),
]


def motion(e, t):
    """q, q̇, q̈ of episode e at times t (each joint's phases shifted by 0.9·e)."""
    out = np.zeros((3, len(NAMES), len(t)))
    for j, (center, terms) in enumerate(BASE):
        out[0, j] = center
        for a, w, p in terms:
            x = w * t + p + 0.9 * e
            out[0, j] += a * np.sin(x)
            out[1, j] += a * w * np.cos(x)
            out[2, j] -= a * w * w * np.sin(x)
    return out


model = pin.buildModelFromUrdf(URDF)
lower, upper = model.lowerPositionLimit, model.upperPositionLimit
gid = model.getJointId("gripper") - 1
span = 1400.0


def stored(q):
    """The dataset's values: DEGREES on the 4095-per-turn lattice, the gripper RANGE_0_100."""
    v = np.zeros((len(NAMES), q.shape[1]), dtype=np.float32)
    for j in range(5):
        deg = np.degrees(SIGNS[j] * (q[j] - OFFSETS[j]))
        v[j] = (np.round(deg * 4095 / 360 + 2047.5) - 2047.5) * 360 / 4095
    v[5] = np.round((q[5] - lower[gid]) / (upper[gid] - lower[gid]) * span) / span * 100
    return v


def table(e, frames, first_index):
    t = np.arange(frames) / FPS
    values = stored(motion(e, t)[0]).T.astype(np.float32)
    vec = pa.FixedSizeListArray.from_arrays(pa.array(values.reshape(-1), pa.float32()), 6)
    return pa.table({
        "action": vec, "observation.state": vec,
        "timestamp": pa.array(t.astype(np.float32)), "frame_index": pa.array(np.arange(frames), pa.int64()),
        "episode_index": pa.array(np.full(frames, e), pa.int64()), "index": pa.array(first_index + np.arange(frames), pa.int64()),
        "task_index": pa.array(np.zeros(frames, dtype=np.int64)),
    })


def info(version, data_path, episodes, frames):
    feature = {"dtype": "float32", "shape": [6], "names": COLUMNS}
    return {"codebase_version": version, "robot_type": "so101_follower", "total_episodes": episodes, "total_frames": episodes * frames,
            "total_tasks": 1, "chunks_size": 1000, "fps": FPS, "splits": {"train": f"0:{episodes}"}, "data_path": data_path, "video_path": None,
            "features": {"action": feature, "observation.state": feature, "timestamp": {"dtype": "float32", "shape": [1], "names": None},
                         "frame_index": {"dtype": "int64", "shape": [1], "names": None}, "episode_index": {"dtype": "int64", "shape": [1], "names": None},
                         "index": {"dtype": "int64", "shape": [1], "names": None}, "task_index": {"dtype": "int64", "shape": [1], "names": None}}}


def write_v3(root, episodes, frames):
    os.makedirs(f"{root}/meta/episodes/chunk-000"); os.makedirs(f"{root}/data/chunk-000")
    json.dump(info("v3.0", "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet", episodes, frames), open(f"{root}/meta/info.json", "w"), indent=4)
    writer = None
    for e in range(episodes):
        t = table(e, frames, e * frames)
        writer = writer or pq.ParquetWriter(f"{root}/data/chunk-000/file-000.parquet", t.schema, compression="snappy")
        writer.write_table(t)
    writer.close()
    pq.write_table(pa.table({"episode_index": list(range(episodes)), "tasks": [["wave"]] * episodes, "length": [frames] * episodes,
                             "data/chunk_index": [0] * episodes, "data/file_index": [0] * episodes,
                             "dataset_from_index": [e * frames for e in range(episodes)], "dataset_to_index": [(e + 1) * frames for e in range(episodes)]}),
                   f"{root}/meta/episodes/chunk-000/file-000.parquet")


def write_v21(root, episodes, frames):
    os.makedirs(f"{root}/meta"); os.makedirs(f"{root}/data/chunk-000")
    json.dump(info("v2.1", "data/chunk-{episode_chunk:03d}/episode_{episode_index:06d}.parquet", episodes, frames), open(f"{root}/meta/info.json", "w"), indent=4)
    with open(f"{root}/meta/episodes.jsonl", "w") as f:
        for e in range(episodes):
            pq.write_table(table(e, frames, e * frames), f"{root}/data/chunk-000/episode_{e:06d}.parquet")
            f.write(json.dumps({"episode_index": e, "tasks": ["wave"], "length": frames}) + "\n")


def exact(e, t, payload):
    m = model.copy()
    if payload > 0:
        frame = m.frames[m.getFrameId(TOOL)]
        m.inertias[frame.parentJoint] = m.inertias[frame.parentJoint] + pin.Inertia(payload, frame.placement.translation, np.zeros((3, 3)))
    d = m.createData()
    q, v, a = motion(e, t)
    index = [m.getJointId(n) - 1 for n in NAMES]
    tau = np.zeros((len(NAMES), len(t)))
    for k in range(len(t)):
        qk, vk, ak = np.zeros(m.nq), np.zeros(m.nv), np.zeros(m.nv)
        qk[index], vk[index], ak[index] = q[:, k], v[:, k], a[:, k]
        tau[:, k] = pin.rnea(m, d, qk, vk, ak)[index]
    return tau


def intervals(time, tau, threshold):
    over = np.abs(tau) > threshold
    out, start = [], None
    for k, o in enumerate(over):
        if o and start is None:
            start = k
        if not o and start is not None:
            out.append((start, k - 1)); start = None
    if start is not None:
        out.append((start, len(over) - 1))
    end = time[-1]
    return [(a, b) for a, b in out if time[a] >= 0.5 and time[b] <= end - 0.5]


frames = SECONDS * FPS + 1
worst_ratio, found = 0.0, 0
worst_share = {n: 0.0 for n in NAMES}  # per joint, the largest error as a share of its peak
with tempfile.TemporaryDirectory() as tmp:
    mapfile = os.path.join(tmp, "map.toml")
    with open(mapfile, "w") as f:
        for j in range(5):
            f.write(f'[joints.{NAMES[j]}]\ncolumn = "{COLUMNS[j]}"\nunit = "deg"\nsign = {SIGNS[j]}\noffset = {OFFSETS[j]}\n\n')
        f.write('[joints.gripper]\ncolumn = "gripper.pos"\nunit = "range_0_100"\n')
    for version, write in [("v3.0", write_v3), ("v2.1", write_v21)]:
        root = os.path.join(tmp, version)
        write(root, 3, frames)
        for payload in [0.0, 0.2]:
            for e in range(3):
                trace = os.path.join(tmp, "trace.csv")
                subprocess.run([armscope, "replay", root, "--urdf", URDF, "--joint-map", mapfile, "--episode", str(e), "--payload", str(payload),
                                "--tool", TOOL, "--trace", trace], check=True, capture_output=True, text=True)
                data = np.genfromtxt(trace, delimiter=",", names=True)
                time = data["t"]
                if len(time) != frames or abs(time[-1] - SECONDS) > 1e-9:
                    sys.exit(f"replay-vs-pinocchio: {version} episode {e}: {len(time)} rows to {time[-1]} s")
                truth = exact(e, time, payload)
                inside = (time >= 0.5) & (time <= time[-1] - 0.5)
                for j, name in enumerate(NAMES):
                    tau = data[f"tau{j + 1}"]
                    err = np.max(np.abs(tau - truth[j])[inside])
                    bar = 0.02 * np.max(np.abs(truth[j][inside])) + 0.005
                    worst_ratio = max(worst_ratio, err / bar)
                    worst_share[name] = max(worst_share[name], err / np.max(np.abs(truth[j][inside])))
                    if err > bar:
                        sys.exit(f"replay-vs-pinocchio: {version} episode {e} payload {payload} kg {name}: error {err:.4f} N·m above {bar:.4f}")
                if payload > 0:
                    a = intervals(time, truth[1], 2.9)
                    b = intervals(time, data["tau2"], 2.9)
                    if len(a) != len(b) or any(abs(x[0] - y[0]) > 1 or abs(x[1] - y[1]) > 1 for x, y in zip(a, b)):
                        sys.exit(f"replay-vs-pinocchio: {version} episode {e}: shoulder_lift over 2.9 N·m, Pinocchio {a}, armscope {b}")
                    found += len(a)
if found < 3:
    sys.exit(f"replay-vs-pinocchio: the motions took shoulder_lift over 2.9 N·m only {found} times")
print(f"replay-vs-pinocchio: v3.0 and v2.1, 3 episodes each, 0 and 0.2 kg: worst error {100 * worst_ratio:.0f} % of the bar "
      f"(2 % of peak + 5 mN·m); {found} intervals of shoulder_lift over 2.9 N·m matched to a frame")
print("replay-vs-pinocchio: worst error per joint, % of its peak: " + ", ".join(f"{n} {100 * v:.2f}" for n, v in worst_share.items()))
