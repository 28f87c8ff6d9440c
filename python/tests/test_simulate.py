"""armscope.simulate: your own controller in the loop, through the same motors, plant and recordings
as `armscope run`'s PD — the tutorial's controller written in Python gives run's trajectory — and a
controller that fails stops the run with one clear exception."""
import warnings

import numpy as np
import pytest

import armscope


@pytest.fixture(scope="module")
def tutorial():
    """The default run (the tutorial's box model, wave and gains) and its controller in Python."""
    reference = armscope.run(duration=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = armscope.Model(reference.summary["urdf"])
    kp, kd = np.array(reference.summary["gains"]["kp"]), np.array(reference.summary["gains"]["kd"])
    amplitude, omega = np.radians(30.0), 0.5
    phases = np.arange(model.nq) * (np.pi / 3)

    def controller(t, q, qd):
        phase = omega * t + phases
        cmd, cmd_dot = amplitude * np.sin(phase), amplitude * omega * np.cos(phase)
        # +g(q) holds the arm: the tutorial's −τ_g
        return kp * (cmd - q) + kd * (cmd_dot - qd) + model.gravity_torque(q)

    return reference, model, controller


def test_the_tutorials_controller_in_python_gives_runs_trajectory(tutorial):
    reference, model, controller = tutorial
    r = armscope.simulate(model, controller, duration=2)
    # 1e-9 rad over the first 2 s (measured 3.7e-13: the sines' last bits, NumPy's against Rust's;
    # past 2 s the tutorial's chattering loop amplifies round-off)
    assert np.abs(r.q - reference.q).max() < 1e-9
    assert np.array_equal(r.t, reference.t) and r.summary["summary"]["status"] == reference.summary["summary"]["status"]


def test_an_object_controller_is_reset_before_the_run(tutorial):
    reference, model, controller = tutorial

    class Counting:
        def __init__(self):
            self.calls, self.resets = 0, 0

        def reset(self):
            self.calls, self.resets = 0, self.resets + 1

        def __call__(self, t, q, qd):
            self.calls += 1
            return controller(t, q, qd)

    c = Counting()
    armscope.simulate(model, c, duration=0.1)
    armscope.simulate(model.urdf, c, duration=0.1)
    assert c.resets == 2 and c.calls == 101, "one call a control step, t = 0 … 0.1 s"


def test_a_controller_that_fails_stops_the_run_with_one_clear_exception(tutorial, tmp_path):
    _, model, _ = tutorial
    zeros = np.zeros(model.nq)
    with pytest.raises(armscope.ArmscopeError, match=r"controller: at t = 0 s: it returned 5 torques, the model has 6 joints"):
        armscope.simulate(model, lambda t, q, qd: np.zeros(5), duration=1)
    with pytest.raises(armscope.ArmscopeError, match="not a finite number for joint 3"):
        armscope.simulate(model, lambda t, q, qd: np.array([0, 0, np.nan, 0, 0, 0.0]), duration=1)
    with pytest.raises(armscope.ArmscopeError, match="not an array of torques"):
        armscope.simulate(model, lambda t, q, qd: "torque", duration=1)

    def late_failure(t, q, qd):
        if t > 0.5:
            raise RuntimeError("the controller broke")
        return zeros

    mcap = tmp_path / "run.mcap"
    with pytest.raises(armscope.ArmscopeError, match=r"at t = 0.501 s: it raised RuntimeError: the controller broke") as caught:
        armscope.simulate(model, late_failure, duration=1, mcap=mcap, no_rrd=True)
    assert isinstance(caught.value.__cause__, RuntimeError)
    # the recording ends whole at the failing step: MCAP's footer magic closes the file
    data = mcap.read_bytes()
    assert data[:8] == b"\x89MCAP0\r\n" and data[-8:] == b"\x89MCAP0\r\n"


def test_ctrl_c_stops_a_long_run_and_its_recording_ends_whole(tmp_path):
    import os
    import signal
    import threading
    import time

    mcap = tmp_path / "long.mcap"
    threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    started = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        armscope.run(duration=3000, mcap=mcap, no_rrd=True)
    # stopped within a second of the signal (the whole run would take minutes)
    assert time.monotonic() - started < 1.5
    data = mcap.read_bytes()
    assert data[:8] == b"\x89MCAP0\r\n" and data[-8:] == b"\x89MCAP0\r\n"
