#!/usr/bin/env python3
"""`armscope model --motors F --urdf-out X` against Pinocchio 4.1 (issue 21 item 2): X loads in
Pinocchio, and its M (plus the rotors' armature, which no URDF field holds; armscope gives it beside M)
and tau_g at random states equal armscope's `model --states` with `--motors F` within 1e-9; the total
mass is the URDF's plus every drive train's. Run by .ci/run with the corpus check's venv."""
import json, re, subprocess, sys, tempfile, os
import xml.etree.ElementTree as ET
import numpy as np
import pinocchio as pin

armscope = sys.argv[1]
repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
cases = [
    ("assets/smallrobot_arm.urdf",
     '[joints.J2]\nmotor = "17HS19-2004S1"\nreduction = "NPS015"\ngear_ratio = 10\n'
     '[joints.J3]\nmotor = "17HS4401"\ngear_ratio = 15\n[joints.J4]\nmotor = "XM430-W350"\n'
     '[joints.J5]\nmotor = "17HS4401"\ngear_ratio = 5\nmount_link = "forearm_link"\nmount_xyz = [0.1, 0.0, 0.03]\n'),
    ("assets/smallrobotarm/smallrobotarm.urdf",
     '[joints.J1]\nmotor = "17HS24-2104S"\nreduction = "CricketDrive-MK2"\n[joints.J2]\nmotor = "17HS19-2004S1"\nreduction = "DYD-14-051"\n'
     '[joints.J3]\nmotor = "17HS4401"\nreduction = "GT2-belt"\ngear_ratio = 4.8\n[joints.J4]\nmotor = "17HS08-1004S"\n[joints.J5]\nmotor = "XL330-M288"\n'),
]
worst = 0.0
with tempfile.TemporaryDirectory() as tmp:
    for urdf, motors in cases:
        urdf = os.path.join(repo, urdf)
        mfile, out = os.path.join(tmp, "motors.toml"), os.path.join(tmp, "out.urdf")
        open(mfile, "w").write(motors)
        made = subprocess.run([armscope, "model", "--urdf", urdf, "--motors", mfile, "--urdf-out", out], check=True, cwd=repo, capture_output=True, text=True)
        carried = float(re.search(r"parts carried, ([0-9.]+) kg", made.stderr).group(1))
        mass = lambda f: sum(float(m.get("value")) for m in ET.parse(f).getroot().iter("mass"))
        if abs(mass(out) - mass(urdf) - carried) > 1e-3:
            sys.exit(f"urdf-out-vs-pinocchio: {out} weighs {mass(out)} kg, not {mass(urdf)} + {carried}")
        model = pin.buildModelFromUrdf(out)
        plain = pin.buildModelFromUrdf(urdf)
        names = [model.names[i] for i in range(1, model.njoints)]
        rng = np.random.default_rng(7)
        states = [{"q": {n: float(x) for n, x in zip(names, rng.uniform(-2, 2, len(names)))}, "v": {}, "tau": {}} for _ in range(20)]
        sfile = os.path.join(tmp, "states.json")
        json.dump(states, open(sfile, "w"))
        result = json.loads(subprocess.run([armscope, "model", "--urdf", urdf, "--motors", mfile, "--states", sfile], check=True, cwd=repo, capture_output=True, text=True).stdout)
        order = [names.index(n) for n in result["joints"]]
        data = model.createData()
        for s, r in zip(states, result["states"]):
            q = np.array([s["q"][n] for n in names])
            M = pin.crba(model, data, q)
            M = np.triu(M) + np.triu(M, 1).T
            M = M[np.ix_(order, order)] + np.diag(result["armature"])
            g = -pin.computeGeneralizedGravity(model, data, q)[order]
            worst = max(worst, np.abs(M - np.array(r["M"])).max(), np.abs(g - np.array(r["tau_g"])).max())
        drive = sum(i.mass for i in model.inertias) - sum(i.mass for i in plain.inertias)
        print(f"{os.path.basename(urdf)}: 20 states; the URDF's mass {mass(urdf):.3f} kg + the drive trains' {carried:.3f} kg; Pinocchio's bodies gain {drive:.3f} kg")
print(f"largest difference in M and tau_g: {worst:.2e}")
if not worst < 1e-9:
    sys.exit("urdf-out-vs-pinocchio: armscope's --urdf-out differs from the model it simulates")
