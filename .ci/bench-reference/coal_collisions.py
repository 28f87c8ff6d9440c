#!/usr/bin/env python3
"""Pinocchio 4.1 + coal doing armscope's collision checks: the same active pairs (from the fixtures in
tests/fixtures/collisions) on the box model and the SmallRobotArm mesh model, 64 random states within the
limits, µs per state for computeDistances (every pair's exact distance) and computeCollisions (yes/no).
Beside `cargo bench --bench collisions`. Run from the repository root with the corpus check's venv:
    python .ci/bench-reference/coal_collisions.py"""
import json, time, sys, numpy as np, pinocchio as pin
for name, urdf in [("box", "assets/smallrobot_arm.urdf"), ("mesh", "assets/smallrobotarm/smallrobotarm.urdf")]:
    fx = json.load(open(f"tests/fixtures/collisions/{'box_model' if name=='box' else 'smallrobotarm_meshes'}.json"))
    model = pin.buildModelFromUrdf(urdf, mimic=True)
    geom = pin.buildGeomFromUrdf(model, urdf, pin.GeometryType.COLLISION, package_dirs=["assets"])
    link_of = [model.frames[g.parentFrame].name for g in geom.geometryObjects]
    for a, b in fx["pairs"]:
        for i, la in enumerate(link_of):
            for j, lb in enumerate(link_of):
                if i < j and {la, lb} == {a, b}:
                    geom.addCollisionPair(pin.CollisionPair(i, j))
    gd, d = pin.GeometryData(geom), model.createData()
    rng = np.random.default_rng(1)
    qs = [np.array([rng.uniform(max(l, -3.14), min(h, 3.14)) for l, h in zip(model.lowerPositionLimit, model.upperPositionLimit)]) for _ in range(64)]
    for what, f in [("computeDistances", lambda q: pin.computeDistances(model, d, geom, gd, q)), ("computeCollisions", lambda q: pin.computeCollisions(model, d, geom, gd, q, False))]:
        n, t0 = 0, time.perf_counter()
        while time.perf_counter() - t0 < 2.0:
            f(qs[n % 64]); n += 1
        print(name, what, (time.perf_counter() - t0) / n * 1e6, "us per state")
