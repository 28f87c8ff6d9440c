#!/usr/bin/env python3
"""MuJoCo's time per step on URDFs (geometry stripped: only the dynamics is timed; contacts off;
Euler, h = 1 ms, as the reference README's MuJoCo setup), from C with mujoco.rollout.
    mujoco_step.py URDF...  ->  one line per model: name nv step_us
MuJoCo's URDF import ignores <mimic>: a mimic joint is an independent degree of freedom there."""
import re
import sys
import time

import mujoco
import numpy as np
from mujoco import rollout

for path in sys.argv[1:]:
    import xml.etree.ElementTree as ET
    root = ET.parse(path).getroot()
    for link in root.findall("link"):
        for tag in ("visual", "collision"):
            for e in link.findall(tag):
                link.remove(e)
        inertia = link.find("inertial/inertia")
        if inertia is not None:  # MuJoCo refuses what is not positive definite (Tiago's 1-gram antenna)
            k = {a: float(inertia.get(a, 0)) for a in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
            tensor = np.array([[k["ixx"], k["ixy"], k["ixz"]], [k["ixy"], k["iyy"], k["iyz"]], [k["ixz"], k["iyz"], k["izz"]]])
            if np.linalg.eigvalsh(tensor).min() <= 0:
                for a in ("ixy", "ixz", "iyz"):
                    inertia.set(a, "0")
                for a in ("ixx", "iyy", "izz"):
                    inertia.set(a, repr(max(abs(k[a]), 1e-9)))
    text = ET.tostring(root, encoding="unicode")
    # MuJoCo refuses inconsistent inertias unless told to balance them (Allegro, PR2, Tiago have some)
    text = re.sub(r"(<robot\b[^>]*>)", r'\1<mujoco><compiler balanceinertia="true" fusestatic="true"/></mujoco>', text, count=1)
    model = mujoco.MjModel.from_xml_string(text)
    model.opt.timestep = 0.001
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    data = mujoco.MjData(model)
    data.qpos[:] = 0.3
    mujoco.mj_forward(model, data)
    state = np.empty(mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS))
    mujoco.mj_getState(model, data, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    nstep = 20000
    best = 1e30
    for _ in range(5):
        t0 = time.perf_counter()
        rollout.rollout(model, data, state[None, :], nstep=nstep)
        best = min(best, (time.perf_counter() - t0) / nstep * 1e6)
    name = re.search(r'<robot\s+name="([^"]*)"', text).group(1)
    print(f"{name} {model.nv} {best:.3f}")
