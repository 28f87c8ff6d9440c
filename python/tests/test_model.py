"""armscope.Model: the algorithms checked against each other (Pinocchio's own identities), a
trajectory against its states one by one, and bad input raised as Python knows it.
Pinocchio itself is the reference in .ci/python-vs-pinocchio.py."""
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest

import armscope

HERE = os.path.dirname(os.path.abspath(__file__))
SO101 = os.path.join(HERE, "..", "..", "tests", "fixtures", "robots", "so101.urdf")


@pytest.fixture(scope="module")
def model():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return armscope.Model(SO101)


def states(model, n, seed=7):
    rng = np.random.default_rng(seed)
    lo, hi = model.lower_position_limit, model.upper_position_limit
    q = rng.uniform(lo, hi, size=(n, model.nq))
    return q, rng.uniform(-1, 1, size=(n, model.nv)), rng.uniform(-1, 1, size=(n, model.nv))


def test_the_urdfs_notices_come_as_warnings():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        armscope.Model(SO101)
    assert any("welding it to the world" in str(w.message) for w in caught), [str(w.message) for w in caught]


def test_shape_and_names(model):
    assert model.nq == model.nv == 6
    assert model.joint_names[:2] == ["shoulder_pan", "shoulder_lift"]
    assert "gripper_link" in model.frame_names
    assert model.lower_position_limit.shape == (6,) and np.all(model.lower_position_limit < model.upper_position_limit)


def test_aba_inverts_rnea_and_rnea_is_m_a_plus_bias(model):
    # 1e-10: a 6-joint arm's dynamics in float64, M's condition about 1e3
    for q, v, a in zip(*states(model, 20)):
        tau = model.rnea(q, v, a)
        assert np.allclose(model.aba(q, v, tau), a, atol=1e-10, rtol=0)
        M = model.mass_matrix(q)
        assert np.allclose(M, M.T, atol=1e-14)
        assert np.all(np.linalg.eigvalsh(M) > 0)
        bias = model.rnea(q, v, np.zeros(6))
        assert np.allclose(tau, M @ a + bias, atol=1e-12)


def test_gravity_torque_is_rnea_at_rest_and_holds_the_arm(model):
    q = np.zeros(6)
    g = model.gravity_torque(q)
    assert np.allclose(g, model.rnea(q, np.zeros(6), np.zeros(6)), atol=1e-14)
    # +g holds the arm: no acceleration at rest
    assert np.allclose(model.aba(q, np.zeros(6), g), 0, atol=1e-10)


def test_jacobian_maps_velocities_to_the_frames_velocity(model):
    # the Jacobian's linear rows against the frame origin's finite-difference velocity
    q, v, _ = states(model, 5, seed=3)
    for qk, vk in zip(q, v):
        J = model.jacobian(qk, "gripper_link")
        h = 1e-6
        p1 = model.frame_pose(qk + h * vk, "gripper_link")[:3, 3]
        p0 = model.frame_pose(qk - h * vk, "gripper_link")[:3, 3]
        assert np.allclose(J[:3] @ vk, (p1 - p0) / (2 * h), atol=1e-8)
        T = model.frame_pose(qk, "gripper_link")
        assert np.allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-12) and np.all(T[3] == [0, 0, 0, 1])


def test_a_trajectory_equals_its_states_one_by_one(model):
    # 50 states (lanes of four and two left over) and 601 (blocks split over the cores): a
    # trajectory's rnea runs four states at a time in SIMD lanes with fused multiply-adds, the
    # one-state call the scalar algorithm, so the two agree to a few roundings, not to the bit
    for count in (50, 601):
        q, v, a = states(model, count)
        taus = model.rnea(q, v, a)
        assert taus.shape == (count, 6)
        one_by_one = np.array([model.rnea(*s) for s in zip(q, v, a)])
        assert np.abs(taus - one_by_one).max() <= 1e-12 * max(1.0, np.abs(one_by_one).max())
    assert model.mass_matrix(q).shape == (count, 6, 6)
    assert np.array_equal(model.frame_pose(q, "gripper_link")[7], model.frame_pose(q[7], "gripper_link"))
    assert np.array_equal(model.jacobian(q, 3)[9], model.jacobian(q[9], 3))
    # lists and other array-likes read as arrays
    assert np.array_equal(model.gravity_torque(q[0].tolist()), model.gravity_torque(q[0]))


def test_bad_input_raises_one_clear_exception(model):
    q = np.zeros(6)
    with pytest.raises(ValueError, match=r"a: shape \[3\], expected \(6,\) or \(N, 6\)"):
        model.rnea(q, q, np.zeros(3))
    with pytest.raises(ValueError, match=r"v: shape \[2, 6\], but q has \[3, 6\]"):
        model.rnea(np.zeros((3, 6)), np.zeros((2, 6)), np.zeros((3, 6)))
    with pytest.raises(ValueError, match="not a finite number"):
        model.gravity_torque([0, 0, np.nan, 0, 0, 0])
    with pytest.raises(TypeError, match="not an array of numbers"):
        model.gravity_torque(["a"] * 6)
    with pytest.raises(ValueError, match="frame 'hand': no such frame"):
        model.frame_pose(q, "hand")
    with pytest.raises(armscope.ArmscopeError, match="nope.urdf"):
        armscope.Model("nope.urdf")


def test_the_command_is_installed_beside_the_package(tmp_path):
    out = subprocess.run(["armscope", "run", "--duration", "0.2", "--no-rrd", "--no-mcap", "--summary-json", "s.json"], cwd=tmp_path, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "s.json").exists()
    bad = subprocess.run(["armscope", "run", "--duration=-1"], cwd=tmp_path, capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "--duration" in bad.stderr


def test_run_gives_the_commands_summary_and_its_trace_as_arrays(tmp_path):
    # armscope.run(no_ff=True) against `armscope run --no-ff --summary-json --trace`, the same run
    r = armscope.run(no_ff=True, duration=0.5)
    cli = subprocess.run(["armscope", "run", "--no-ff", "--duration=0.5", "--no-rrd", "--no-mcap", "--quiet", "--summary-json", "s.json", "--trace", "t.csv"], cwd=tmp_path, capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    import json
    expected = json.loads((tmp_path / "s.json").read_text())
    for doc in (expected, r.summary):
        doc["summary"].pop("wall_time", None)
    assert r.summary == expected
    trace = np.loadtxt(tmp_path / "t.csv", delimiter=",", skiprows=1)
    n = r.q.shape[1]
    assert r.t.shape == (trace.shape[0],) and np.array_equal(r.t, trace[:, 0])
    for k, name in enumerate(["q", "qd", "q_target", "qd_target", "tau", "tau_g"]):
        assert np.array_equal(getattr(r, name), trace[:, 1 + k * n : 1 + (k + 1) * n]), name
    assert np.array_equal(r.tool_position, trace[:, -3:])
    assert r.saturated.dtype == bool and r.saturated.shape == r.q.shape and r.duty is None


def test_run_refuses_an_unknown_flag_or_a_bad_value_in_one_line():
    with pytest.raises(armscope.ArmscopeError, match="unexpected argument '--bogus"):
        armscope.run(bogus=1)
    with pytest.raises(armscope.ArmscopeError, match="--duration"):
        armscope.run(duration=-1)


def test_replay_gives_each_episodes_motion_and_the_torque_it_needed(model, tmp_path):
    # a table named by joint (SI units): the needed torque is the model's inverse dynamics along the
    # smoothed motion the replay returns, to round-off
    t = np.arange(0, 4, 1 / 30)
    q = np.stack([0.3 * np.sin(1.3 * t + j) for j in range(model.nq)], axis=1)
    csv = tmp_path / "motion.csv"
    np.savetxt(csv, np.column_stack([t, q]), delimiter=",", header="t," + ",".join(model.joint_names), comments="")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        (ep,) = armscope.replay(csv, SO101)
    assert ep.q.shape == (t.size, model.nq) and np.allclose(ep.t, t)
    assert np.allclose(ep.tau, model.rnea(ep.q, ep.qd, ep.qdd), atol=1e-9, rtol=0)
    assert [v["joint"] for v in ep.verdicts] == model.joint_names
    peak = [v["peak_torque"] for v in ep.verdicts]
    assert np.allclose(peak, np.abs(ep.tau).max(axis=0), atol=1e-12)
    with pytest.raises(armscope.ArmscopeError, match="units: 'furlongs'"):
        armscope.replay(csv, SO101, units="furlongs")


def test_a_replay_past_a_urdf_limit_is_followed_to_it_and_said_in_one_warning(model, tmp_path):
    # elbow_flex's URDF limit is 1.69 rad: a real arm's 3 degrees past it is followed to the limit
    t = np.arange(0, 4, 1 / 30)
    elbow = model.joint_names.index("elbow_flex")
    q = np.stack([0.3 * np.sin(1.3 * t + j) for j in range(model.nq)], axis=1)
    q[:, elbow] = 1.39 + (0.3 + np.radians(3)) * np.sin(1.3 * t)
    csv = tmp_path / "past.csv"
    np.savetxt(csv, np.column_stack([t, q]), delimiter=",", header="t," + ",".join(model.joint_names), comments="")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        (ep,) = armscope.replay(csv, SO101)
    past = [str(w.message) for w in caught if "past the URDF's limits" in str(w.message)]
    assert len(past) == 1 and "elbow_flex by up to" in past[0], past
    assert ep.q[:, elbow].max() <= 1.69 + 1e-12
