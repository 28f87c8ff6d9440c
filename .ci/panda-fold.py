#!/usr/bin/env python3
"""The Panda (example-robot-data, its SRDF beside the URDF) folding onto itself
(assets/experiments/panda_fold.csv): a run with --stop-on-collision stops at the first contact (exit 4)
with both recordings whole — the .mcap's summary section read by the mcap package, its /collisions
channel's last message in contact; the run without the flag reports the same first contact.
Usage: panda-fold.py ARMSCOPE_BINARY"""
import json, subprocess, sys, tempfile, os
sys.path.insert(0, os.path.dirname(__file__))
from example_robots import robots_dir

armscope = sys.argv[1]
urdf = os.path.join(robots_dir(), "panda_description", "urdf", "panda.urdf")
with tempfile.TemporaryDirectory() as d:
    full, stop = os.path.join(d, "full.json"), os.path.join(d, "stop.json")
    rrd, mcap_path = os.path.join(d, "fold.rrd"), os.path.join(d, "fold.mcap")
    base = [armscope, "run", "--quiet", "--urdf", urdf, "--trajectory", "assets/experiments/panda_fold.csv"]
    r = subprocess.run(base + ["--collisions", "--no-rrd", "--no-mcap", "--summary-json", full], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    first = json.load(open(full))["summary"]["collisions"]["first_contact"]
    r = subprocess.run(base + ["--stop-on-collision", "--rrd", rrd, "--mcap", mcap_path, "--summary-json", stop], capture_output=True, text=True)
    assert r.returncode == 4, (r.returncode, r.stderr)
    status = json.load(open(stop))["summary"]["status"]
    assert [status["time"], status["link1"], status["link2"]] == first, (status, first)
    from mcap.reader import make_reader
    with open(mcap_path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary is not None and summary.statistics.message_count > 0, "the .mcap was closed properly"
        topics = {c.topic for c in summary.channels.values()}
        assert {"/collisions", "/collisions/contacts"} <= topics, topics
    assert os.path.getsize(rrd) > 0
    print(f"panda-fold: first contact t = {first[0]:.3f} s, {first[1]} with {first[2]}; --stop-on-collision stopped there (exit 4), both files whole")
