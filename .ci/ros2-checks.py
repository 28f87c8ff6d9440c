#!/usr/bin/env python3
"""The ROS 2 encoding of armscope's MCAP against real ROS 2 clients (run by .ci/ros2-checks in a venv
with rosbags, mcap-ros2-support, mcap and rerun-sdk): for the default run and a Panda run written with
--mcap-encoding ros2,
- the file: header profile ros2; every channel cdr with a ros2msg schema and rosbag2's
  offered_qos_profiles; a Statistics record and chunk indexes;
- rosbags opens it as a rosbag2 with an empty type store and decodes every message from the
  definitions in the file;
- mcap-ros2-support decodes every message;
- `rerun mcap check --full` finds no issue, and `rerun mcap convert` gives /joint_states/position,
  /velocity and /effort as scalars named by the URDF's joints, equal to the run's --trace at every step,
  and /tf as transforms;
- /robot_description is the URDF."""
import csv, os, subprocess, sys, tempfile

import yaml
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore
from rerun.experimental import RrdReader

armscope, rerun_cli = os.path.abspath(sys.argv[1]), sys.argv[2]
erd = sys.argv[3]  # example-robot-data's robots folder
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def meta(field, key):
    return (field.metadata or {}).get(key.encode(), b"").decode()


def scalars(rrd, entity):
    """Every row of `entity`'s Scalars on message_log_time, and its series names."""
    reader = RrdReader(rrd)
    store = reader.recordings()[0]
    rows, names = [], None
    for ch in reader.stream(store=store):
        if ch.entity_path != entity or ch.is_static:
            continue
        rb = ch.to_record_batch()
        time = [f for f in rb.schema if meta(f, "rerun:kind") == "index" and (meta(f, "rerun:index_name") or f.name) == "message_log_time"][0]
        data = {meta(f, "rerun:component"): f for f in rb.schema if meta(f, "rerun:kind") == "data"}
        values = rb.column(data["Scalars:scalars"].name).to_pylist()
        if names is None and "SeriesLines:names" in data:
            names = rb.column(data["SeriesLines:names"].name).to_pylist()[0]
        rows += zip(rb.column(time.name).cast("int64").to_pylist(), values)
    rows.sort()
    return rows, names


with tempfile.TemporaryDirectory() as tmp:
    panda = os.path.join(erd, "panda_description", "urdf", "panda.urdf")
    for label, urdf, extra in [("default", None, []), ("panda", panda, ["--duration", "5"])]:
        mcap_path, trace = os.path.join(tmp, f"{label}.mcap"), os.path.join(tmp, f"{label}.csv")
        args = [armscope, "run", "--quiet", "--mcap-encoding", "ros2", "--mcap", mcap_path, "--no-rrd", "--trace", trace, *extra]
        if urdf:
            args += ["--urdf", urdf]
        subprocess.run(args, check=True)
        with open(mcap_path, "rb") as f:
            reader = make_reader(f, decoder_factories=[DecoderFactory()])
            header, summary = reader.get_header(), reader.get_summary()
            check(header.profile == "ros2", f"{label}: header profile {header.profile!r}")
            bad = [c.topic for c in summary.channels.values() if c.message_encoding != "cdr" or summary.schemas[c.schema_id].encoding != "ros2msg"]
            check(not bad, f"{label}: every channel cdr with a ros2msg schema ({len(summary.channels)} channels){': not ' + str(bad) if bad else ''}")
            qos = {c.topic: yaml.safe_load(c.metadata.get("offered_qos_profiles", "")) for c in summary.channels.values()}
            check(all(isinstance(q, list) and q and {"history", "depth", "reliability", "durability"} <= set(q[0]) for q in qos.values()), f"{label}: every channel's offered_qos_profiles")
            check(qos["/robot_description"][0]["durability"] == 1 and qos["/tf_static"][0]["durability"] == 1 and qos["/joint_states"][0]["durability"] == 2, f"{label}: transient local for /robot_description and /tf_static, volatile for the rest")
            check(summary.statistics is not None and summary.statistics.message_count > 0 and len(summary.chunk_indexes) > 0, f"{label}: a Statistics record ({summary.statistics.message_count} messages) and {len(summary.chunk_indexes)} chunk indexes")
            decoded = 0
            for _, _, _, message in reader.iter_decoded_messages():
                decoded += 1
            check(decoded == summary.statistics.message_count, f"{label}: mcap-ros2-support decoded {decoded} of {summary.statistics.message_count} messages")
        # rosbags: a rosbag2 read with an empty type store, every type from the file's definitions
        with AnyReader([__import__("pathlib").Path(mcap_path)], default_typestore=get_typestore(Stores.EMPTY)) as bag:
            count, description = 0, None
            for connection, _, raw in bag.messages():
                message = bag.deserialize(raw, connection.msgtype)
                count += 1
                if connection.topic == "/robot_description":
                    description = message.data
            check(count == summary.statistics.message_count, f"{label}: rosbags decoded {count} messages of {len(bag.connections)} connections")
        urdf_text = open(urdf or os.path.join(os.path.dirname(armscope), "..", "..", "assets", "smallrobot_arm.urdf")).read()
        check(description == urdf_text, f"{label}: /robot_description is the URDF ({len(urdf_text)} characters)")
        # Rerun's own importer
        checked = subprocess.run([rerun_cli, "mcap", "check", "--full", mcap_path], capture_output=True, text=True)
        issues = [l for l in checked.stdout.splitlines() if l.startswith(("warn", "error", "FAIL", "fail"))]
        check(checked.returncode == 0 and not issues, f"{label}: rerun mcap check --full{': ' + str(issues) if issues else ''}")
        rrd = os.path.join(tmp, f"{label}.rrd")
        subprocess.run([rerun_cli, "mcap", "convert", mcap_path, "-o", rrd], check=True, capture_output=True)
        with open(trace) as f:
            rows = list(csv.DictReader(f))
        n = sum(1 for k in rows[0] if k.startswith("q") and not k.startswith("qd"))
        for leaf, prefix in [("position", "q"), ("velocity", "qd"), ("effort", "u")]:
            series, names = scalars(rrd, f"/joint_states/{leaf}")
            expected = [[float(r[f"{prefix}{j + 1}"]) for j in range(n)] for r in rows]
            same = len(series) == len(expected) and all(list(v) == e for (_, v), e in zip(series, expected))
            check(same, f"{label}: /joint_states/{leaf} in Rerun equals the trace at all {len(expected)} steps")
        check(names is not None and len(names) == n, f"{label}: the series are named by the joints: {names}")
        reader = RrdReader(rrd)
        entities = {ch.entity_path for ch in reader.stream(store=reader.recordings()[0])}
        check("/tf" in entities and "/tf_static" in entities, f"{label}: /tf and /tf_static as transforms")
if failures:
    sys.exit(f"ros2-checks: {len(failures)} failed")
print("ros2-checks: both files read as rosbag2 bags by rosbags, mcap-ros2-support and Rerun")
