#!/usr/bin/env python3
"""armscope's collision checks against Pinocchio 4.1 + coal on the same geometry and the same pairs:
at 300 random states within the limits of the box model, UR5, Panda, SO-100 and Kinova's arm (COLLADA
meshes; example-robot-data 6.0.0, their SRDFs), every active pair armscope reports closer than 5 cm has
coal's distance within 1e-6 m (primitives) / 1e-5 m (meshes) when both are apart, and the pairs coal's
collide() finds colliding are the ones armscope finds in contact, except pairs within 1 mm of touching.
Meshes are triangle surfaces on both sides (coal's BVH, parry's TriMesh): a shape wholly inside another's
mesh is apart for both. Run by .ci/run with the corpus check's venv."""
import json, os, subprocess, sys, tempfile
import numpy as np
import pinocchio as pin

armscope = os.path.abspath(sys.argv[1])
repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
from example_robots import robots_dir as find_robots
robots_dir = find_robots()
def erd(rel):
    p = os.path.join(robots_dir, rel)
    if not os.path.exists(p):
        sys.exit(f"collisions-vs-coal: {rel} not found under {robots_dir}")
    return p

cases = [
    ("box model", os.path.join(repo, "assets/smallrobot_arm.urdf"), None, 1e-6),
    ("ur5", erd("ur_description/urdf/ur5_robot.urdf"), erd("ur_description/srdf/ur5.srdf"), 1e-5),
    ("panda", erd("panda_description/urdf/panda.urdf"), erd("panda_description/srdf/panda.srdf"), 1e-5),
    ("so100", erd("so_arm_description/urdf/so100.urdf"), None, 1e-5),
    # every collision mesh a COLLADA file
    ("kinova", erd("kinova_description/robots/kinova.urdf"), erd("kinova_description/srdf/kinova.srdf"), 1e-5),
]
package_dir = os.path.dirname(os.path.dirname(robots_dir))
failed = False
with tempfile.TemporaryDirectory() as tmp:
    for name, urdf, srdf, tol in cases:
        model = pin.buildModelFromUrdf(urdf, mimic=True)
        geom = pin.buildGeomFromUrdf(model, urdf, pin.GeometryType.COLLISION, package_dirs=[package_dir, os.path.dirname(urdf)])
        rng = np.random.default_rng(11)
        lo, hi = model.lowerPositionLimit, model.upperPositionLimit
        # one angle per joint; a continuous joint is (cos, sin) in Pinocchio's q
        qs, states = [], []
        for _ in range(300):
            q, angles = pin.neutral(model), {}
            for j in range(1, model.njoints):
                i, joint = model.joints[j].idx_q, model.names[j]
                if model.joints[j].nq == 0:
                    continue  # a mimic joint follows its leader
                if model.joints[j].nq == 2:
                    a = rng.uniform(-np.pi, np.pi)
                    q[i:i + 2] = np.cos(a), np.sin(a)
                else:
                    a = rng.uniform(max(lo[i], -np.pi), min(hi[i], np.pi))
                    q[i] = a
                angles[joint] = float(a)
            qs.append(q)
            states.append({"q": angles, "v": {}, "tau": {}})
        sfile = os.path.join(tmp, "states.json")
        json.dump(states, open(sfile, "w"))
        cmd = [armscope, "model", "--urdf", urdf, "--collisions", "--states", sfile] + (["--srdf", srdf] if srdf else [])
        result = json.loads(subprocess.run(cmd, check=True, cwd=repo, capture_output=True, text=True).stdout)
        pairs = [tuple(p) for p in result["collision_pairs"]]
        link_of = [model.frames[g.parentFrame].name for g in geom.geometryObjects]
        index = {}
        for a, b in pairs:
            for i, la in enumerate(link_of):
                for j, lb in enumerate(link_of):
                    if i < j and {la, lb} == {a, b}:
                        index.setdefault((a, b), []).append(len(geom.collisionPairs))
                        geom.addCollisionPair(pin.CollisionPair(i, j))
        gdata = pin.GeometryData(geom)
        data = model.createData()
        worst, contact_mismatch, compared, in_contact, colliding = 0.0, 0, 0, 0, 0
        for q, r in zip(qs, result["states"]):
            pin.computeDistances(model, data, geom, gdata, q)
            coal = {p: min(gdata.distanceResults[k].min_distance for k in ks) for p, ks in index.items()}
            pin.computeCollisions(model, data, geom, gdata, q, False)
            coal_collides = {p: any(gdata.collisionResults[k].isCollision() for k in ks) for p, ks in index.items()}
            ours = {(c["link1"], c["link2"]): c["distance"] for c in r["collisions"]}
            ours = {((a, b) if (a, b) in coal else (b, a)): d for (a, b), d in ours.items()}
            for p, dc in coal.items():
                da = ours.get(p)
                # the colliding pairs: coal's collide() against armscope's contact, but for pairs
                # within 1 mm of touching
                ours_collides = da is not None and da <= 0
                colliding += coal_collides[p]
                if coal_collides[p] != ours_collides and not (da is not None and 0 < da < 1e-3) and not (0 < dc < 1e-3):
                    contact_mismatch += 1
                    print(f"  {name}: {p} coal {'collides' if coal_collides[p] else 'apart'} ({dc:+.6f} m), armscope {da} m")
                if dc > 0.05 + tol:
                    if da is not None:
                        worst = max(worst, abs(da - dc)) if da > 0 else worst
                    continue
                if abs(dc) < 1e-3 or (da is not None and abs(da) < 1e-3):
                    continue  # within 1 mm of touching: either answer
                if da is None:
                    if dc < 0.05 - tol:
                        print(f"  {name}: {p} coal {dc:.6f} m, armscope reports it farther than 5 cm")
                        failed = True
                    continue
                if (dc <= 0) != (da <= 0):
                    contact_mismatch += 1
                    print(f"  {name}: {p} coal {dc:+.6f} m, armscope {da:+.6f} m")
                elif dc > 0:
                    if abs(da - dc) > tol and abs(da - dc) > worst:
                        print(f"  {name}: {p} coal {dc:.9f} m, armscope {da:.9f} m")
                    worst = max(worst, abs(da - dc))
                    compared += 1
                else:
                    in_contact += 1
        ok = worst <= tol and contact_mismatch == 0
        failed |= not ok
        print(f"{name}: {len(pairs)} active pairs, 300 states: {compared} distances under 5 cm compared, largest difference {worst:.1e} m (bar {tol:.0e}); {in_contact} pair-states in contact on both sides, {colliding} colliding for coal's collide(), {contact_mismatch} disagreeing")
if failed:
    sys.exit("collisions-vs-coal: armscope's collision checks disagree with Pinocchio + coal")
print("collisions-vs-coal: armscope agrees with Pinocchio 4.1 + coal on every robot")
