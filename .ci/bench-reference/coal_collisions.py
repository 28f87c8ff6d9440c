#!/usr/bin/env python3
"""Pinocchio 4.1 + coal doing armscope's collision checks, µs per state for computeDistances (every
pair's exact distance) and computeCollisions (yes/no), beside `cargo bench --bench collisions`:
- the box model and the SmallRobotArm mesh model, the same active pairs (from the fixtures in
  tests/fixtures/collisions), 64 random states within the limits (the `collision_check` group);
- the Panda (example-robot-data, its SRDF's pairs as armscope reads them) along the states of the 3 s
  ±90° wave the `run_3s/panda` group simulates (its trace, written by ARMSCOPE_BINARY), every step.
Run from the repository root with the corpus check's venv:
    python .ci/bench-reference/coal_collisions.py [ARMSCOPE_BINARY]"""
import csv, json, os, subprocess, sys, tempfile, time
import numpy as np
import pinocchio as pin


def timed(name, model, geom, qs):
    gd, d = pin.GeometryData(geom), model.createData()
    for what, f in [("computeDistances", lambda q: pin.computeDistances(model, d, geom, gd, q)), ("computeCollisions", lambda q: pin.computeCollisions(model, d, geom, gd, q, False))]:
        n, t0 = 0, time.perf_counter()
        while time.perf_counter() - t0 < 2.0:
            f(qs[n % len(qs)]); n += 1
        print(name, what, round((time.perf_counter() - t0) / n * 1e6, 2), "us per state")


def add_pairs(model, geom, pairs):
    link_of = [model.frames[g.parentFrame].name for g in geom.geometryObjects]
    for a, b in pairs:
        for i, la in enumerate(link_of):
            for j, lb in enumerate(link_of):
                if i < j and {la, lb} == {a, b}:
                    geom.addCollisionPair(pin.CollisionPair(i, j))


for name, urdf in [("box", "assets/smallrobot_arm.urdf"), ("mesh", "assets/smallrobotarm/smallrobotarm.urdf")]:
    fx = json.load(open(f"tests/fixtures/collisions/{'box_model' if name=='box' else 'smallrobotarm_meshes'}.json"))
    model = pin.buildModelFromUrdf(urdf, mimic=True)
    geom = pin.buildGeomFromUrdf(model, urdf, pin.GeometryType.COLLISION, package_dirs=["assets"])
    add_pairs(model, geom, fx["pairs"])
    rng = np.random.default_rng(1)
    qs = [np.array([rng.uniform(max(l, -3.14), min(h, 3.14)) for l, h in zip(model.lowerPositionLimit, model.upperPositionLimit)]) for _ in range(64)]
    timed(name, model, geom, qs)

if len(sys.argv) > 1:
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    from example_robots import robots_dir
    armscope, robots = os.path.abspath(sys.argv[1]), robots_dir()
    urdf = os.path.join(robots, "panda_description/urdf/panda.urdf")
    with tempfile.TemporaryDirectory() as tmp:
        trace = os.path.join(tmp, "trace.csv")
        subprocess.run([armscope, "run", "--quiet", "--urdf", urdf, "--amp-deg", "90", "--duration", "3", "--no-rrd", "--no-mcap", "--trace", trace], check=True, capture_output=True)
        rows = list(csv.DictReader(open(trace)))
        no_states = os.path.join(tmp, "states.json")
        open(no_states, "w").write("[]")
        pairs = json.loads(subprocess.run([armscope, "model", "--urdf", urdf, "--collisions", "--states", no_states], capture_output=True, text=True).stdout or "{}").get("collision_pairs")
    model = pin.buildModelFromUrdf(urdf, mimic=True)
    geom = pin.buildGeomFromUrdf(model, urdf, pin.GeometryType.COLLISION, package_dirs=[os.path.dirname(os.path.dirname(robots)), os.path.dirname(urdf)])
    if pairs is None:
        sys.exit("coal_collisions: armscope model --collisions --states gave no pairs")
    add_pairs(model, geom, pairs)
    # the trace's joint columns in armscope's joint order, which is Pinocchio's for the Panda
    columns = [k for k in rows[0] if k.startswith("q") and k[1:].isdigit()]
    qs = [np.array([float(r[c]) for c in columns] + [0.0] * (model.nq - len(columns))) for r in rows]
    print(f"panda: {len(pairs)} pairs, {len(qs)} states of the ±90° wave")
    timed("panda wave", model, geom, qs)
