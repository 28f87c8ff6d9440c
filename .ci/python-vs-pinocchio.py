#!/usr/bin/env python3
"""armscope's Python package against Pinocchio's Python API on the fixed-base robots of
example-robot-data: at random states, by joint and frame name, rnea (one state at a time and all at
once, as a trajectory), aba, the mass matrix, the generalized gravity, every link frame's pose and its
LOCAL_WORLD_ALIGNED Jacobian, each within --tolerance of its scale. Then the speed side by side: one rnea call from Python, and rnea over a
10 000-state trajectory against a Python loop of pin.rnea.

Run by .ci/run in the corpus venv (pin, example-robot-data) with the armscope wheel installed:
    python-vs-pinocchio.py [--tolerance 1e-9]
"""
import argparse
import os
import sys
import timeit
import warnings

import numpy as np
import pinocchio as pin

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from example_robots import ROBOTS, robots_dir  # noqa: E402

import armscope  # noqa: E402


def coordinates(model, names):
    """Per armscope coordinate (by joint name): Pinocchio's joint model."""
    by_name = {model.names[j]: model.joints[j] for j in range(1, model.njoints)}
    return [by_name[n] for n in names]


def pin_q(model, joints, q):
    """Pinocchio's configuration of armscope's angles (a continuous joint as cos, sin)."""
    out = pin.neutral(model)
    for jm, angle in zip(joints, q):
        if jm.nq == 2:
            out[jm.idx_q : jm.idx_q + 2] = [np.cos(angle), np.sin(angle)]
        else:
            out[jm.idx_q] = angle
    return out


def rel(a, b):
    scale = max(1.0, float(np.abs(b).max()) if np.size(b) else 1.0)
    return float(np.abs(np.asarray(a) - np.asarray(b)).max()) / scale if np.size(b) else 0.0


def compare(urdf, rng, states=9):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ours = armscope.Model(urdf)
    model = pin.buildModelFromUrdf(urdf, mimic=True)
    data = model.createData()
    joints = coordinates(model, ours.joint_names)
    v_idx = np.array([jm.idx_v for jm in joints])
    assert model.nv == ours.nv, f"nv {ours.nv} vs Pinocchio's {model.nv}"
    lo, hi = ours.lower_position_limit, ours.upper_position_limit
    finite = np.isfinite(lo) & np.isfinite(hi) & (hi > lo) & (hi - lo < 2 * np.pi)
    links = [f for f in ours.frame_names if model.existFrame(f, pin.FrameType.BODY)]
    mimic = model.nvExtended != model.nv
    worst = dict.fromkeys(["rnea", "aba", "M", "g", "poses", "J"], 0.0)
    trajectory, expected = ([], [], []), []  # the states at once: rnea's SIMD lanes
    for _ in range(states):
        q = np.where(finite, rng.uniform(np.where(finite, lo, -np.pi), np.where(finite, hi, np.pi)), rng.uniform(-np.pi, np.pi, ours.nq))
        v, a, tau = (rng.uniform(-1, 1, ours.nv) for _ in range(3))
        pq = pin_q(model, joints, q)
        P = lambda x: x[v_idx]  # Pinocchio's velocity vector in armscope's order  # noqa: E731
        pv, pa, ptau = (np.zeros(model.nv) for _ in range(3))
        pv[v_idx], pa[v_idx], ptau[v_idx] = v, a, tau
        M = pin.crba(model, data, pq)
        M = np.triu(M) + np.triu(M, 1).T
        if mimic:  # Pinocchio's RNEA and ABA refuse mimic joints: M·a + nle, and its solve
            nle = pin.nonLinearEffects(model, data, pq, pv).copy()
            rnea, aba = M @ pa + nle, np.linalg.solve(M, ptau - nle)
        else:
            rnea, aba = pin.rnea(model, data, pq, pv, pa).copy(), pin.aba(model, data, pq, pv, ptau).copy()
        worst["rnea"] = max(worst["rnea"], rel(ours.rnea(q, v, a), P(rnea)))
        for rows, x in zip(trajectory, (q, v, a)):
            rows.append(x)
        expected.append(P(rnea))
        worst["aba"] = max(worst["aba"], rel(ours.aba(q, v, tau), P(aba)))
        worst["M"] = max(worst["M"], rel(ours.mass_matrix(q), M[np.ix_(v_idx, v_idx)]))
        worst["g"] = max(worst["g"], rel(ours.gravity_torque(q), P(pin.computeGeneralizedGravity(model, data, pq))))
        pin.computeJointJacobians(model, data, pq)
        pin.updateFramePlacements(model, data)
        for link in links:
            fid = model.getFrameId(link, pin.FrameType.BODY)
            worst["poses"] = max(worst["poses"], rel(ours.frame_pose(q, link), data.oMf[fid].homogeneous))
            J = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            worst["J"] = max(worst["J"], rel(ours.jacobian(q, link), J[:, v_idx]))
    many = ours.rnea(*(np.array(rows) for rows in trajectory))
    worst["rnea"] = max([worst["rnea"]] + [rel(got, want) for got, want in zip(many, expected)])
    return ours, model, worst, len(links)


def speed(urdf, rounds=7):
    """One rnea call from Python, armscope's and Pinocchio's; a 10 000-state trajectory at once
    against a Python loop of pin.rnea. The two are timed in turn, round after round (this machine's
    speed drifts by tens of percent within a minute): each round's ratio, of the best of a few calls
    each; the rounds' median and range."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ours = armscope.Model(urdf)
    model = pin.buildModelFromUrdf(urdf)
    data = model.createData()
    rng = np.random.default_rng(1)
    q, v, a = (rng.uniform(-1, 1, model.nv) for _ in range(3))
    Q, V, A = (rng.uniform(-1, 1, (10000, model.nv)) for _ in range(3))

    def loop():
        for k in range(10000):
            pin.rnea(model, data, Q[k], V[k], A[k])

    one, trajectory = [], []
    n = 20000
    for _ in range(rounds):
        one_ours = min(timeit.repeat(lambda: ours.rnea(q, v, a), number=n, repeat=3)) / n
        one_pin = min(timeit.repeat(lambda: pin.rnea(model, data, q, v, a), number=n, repeat=3)) / n
        # warm: the cores woken (the loop before left one idle), as in a notebook's repeated calls
        ours.rnea(Q, V, A)
        traj_ours = min(timeit.repeat(lambda: ours.rnea(Q, V, A), number=10, repeat=3)) / 10
        traj_pin = min(timeit.repeat(loop, number=1, repeat=2))
        one.append((one_pin / one_ours, one_ours, one_pin))
        trajectory.append((traj_pin / traj_ours, traj_ours, traj_pin))
    return sorted(one), sorted(trajectory)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tolerance", type=float, default=1e-9)
    a = ap.parse_args()
    root = robots_dir()
    rng = np.random.default_rng(20261128)
    failures = []
    print("| robot | nq | links | rnea | aba | M | g | frame poses | Jacobians |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, path in ROBOTS.items():
        try:
            ours, model, worst, links = compare(os.path.join(root, path), rng)
        except Exception as e:  # noqa: BLE001  (the table says which robot and why)
            failures.append(f"{name}: {e}")
            print(f"| {name} | FAILED: {e} |")
            continue
        bad = [k for k, w in worst.items() if not w <= a.tolerance]
        failures += [f"{name}: {k} differs by {worst[k]:.1e}" for k in bad]
        print(f"| {name} | {ours.nq} | {links} | " + " | ".join(f"{worst[k]:.1e}" for k in ["rnea", "aba", "M", "g", "poses", "J"]) + " |")
    one, trajectory = speed(os.path.join(root, ROBOTS["ur5"]))
    (ratio, ours_s, pin_s), (traj_ratio, traj_ours, traj_pin) = one[len(one) // 2], trajectory[len(trajectory) // 2]
    print(f"\nUR5 rnea from Python, {len(one)} rounds in turn, medians: armscope {1e6 * ours_s:.2f} µs a call, pin.rnea {1e6 * pin_s:.2f} µs "
          f"({ratio:.2f}×; rounds {one[0][0]:.2f}–{one[-1][0]:.2f}×); 10 000 states at once {1e3 * traj_ours:.2f} ms against a Python loop of "
          f"pin.rnea {1e3 * traj_pin:.2f} ms ({traj_ratio:.1f}×; rounds {trajectory[0][0]:.1f}–{trajectory[-1][0]:.1f}×)")
    if failures:
        sys.exit("python-vs-pinocchio: " + "; ".join(failures))
    print(f"python-vs-pinocchio: {len(ROBOTS)} robots within {a.tolerance:g} of Pinocchio {pin.__version__}")


if __name__ == "__main__":
    main()
