"""armscope: a robot arm's rigid-body dynamics, motors and recordings, from Python.

The same library as the ``armscope`` command, NumPy in and out::

    import armscope
    m = armscope.Model("so101.urdf")
    tau = m.rnea(q, v, a)            # one state: (nq,) arrays
    taus = m.rnea(Q, V, A)           # a trajectory: (N, nq) arrays, the GIL released
    r = armscope.run(no_ff=True, duration=30)   # `armscope run --no-ff --duration 30`, as arrays

Bad input raises :class:`ArmscopeError` (what armscope refused, in the command line's one line),
``ValueError`` (an array of the wrong shape) or ``TypeError``.
"""

import json
import os
import sys

from . import _armscope
from ._armscope import ArmscopeError, Model
from ._armscope import main as _main

__all__ = ["ArmscopeError", "Episode", "Model", "Run", "batch", "main", "replay", "run", "simulate", "size"]


class Run:
    """One run's every control step as NumPy arrays, and its summary.

    ``t`` (N,); per joint, (N, nq): ``q``, ``q_target``, ``qd``, ``qd_target``, ``tau`` (the torque
    applied, after the motors' limits), ``tau_g`` (the force gravity applies, Drake's sign),
    ``tau_limit`` (the limit in the direction asked, at that speed), ``saturated`` (bool);
    ``tool_position`` (N, 3), m; where the joints have bus servos, their ``duty`` and ``current``
    (None otherwise). ``summary`` is the dict ``--summary-json`` writes.
    """

    def __init__(self, arrays, summary):
        self.t = arrays["t"]
        self.q = arrays["q"]
        self.q_target = arrays["q_target"]
        self.qd = arrays["qd"]
        self.qd_target = arrays["qd_target"]
        self.tau = arrays["tau"]
        self.tau_g = arrays["tau_g"]
        self.tau_limit = arrays["tau_limit"]
        self.saturated = arrays["saturated"]
        self.tool_position = arrays["tool_position"]
        self.duty = arrays.get("duty")
        self.current = arrays.get("current")
        self.summary = summary

    def __repr__(self):
        status = self.summary.get("summary", {}).get("status")
        return f"armscope.Run({self.t.size} steps of {self.q.shape[1]} joints, {status!r})"


def _argv(flags):
    """``run``'s keyword arguments as its flags: ``no_ff=True`` → ``--no-ff``; False and None left
    out; a list joined by commas; ``--flag=value`` so that a negative number reads as a value."""
    argv = []
    for key, value in flags.items():
        flag = "--" + key.replace("_", "-")
        if value is None or value is False:
            continue
        if value is True:
            argv.append(flag)
        elif isinstance(value, (list, tuple)):
            argv.append(f"{flag}={','.join(str(x) for x in value)}")
        else:
            argv.append(f"{flag}={os.fspath(value) if isinstance(value, os.PathLike) else value}")
    return argv


def run(**flags) -> Run:
    """``armscope run`` with ``flags`` (its flags by name, ``-`` as ``_``: ``run(urdf="arm.urdf",
    motors="m.toml", duration=30, no_ff=True)``), its samples returned as a :class:`Run`. No file is
    written unless asked (``rrd=``, ``mcap=``, ``trace=``, ``csv=``, ``summary_json=``). The run goes
    on without the GIL; an unknown flag or a bad value raises ArmscopeError with the command line's
    line."""
    return _run(_argv(flags))


def simulate(model, controller, **flags) -> Run:
    """Run ``model`` (an armscope.Model or a URDF's path) with your own ``controller`` in the loop:
    ``controller(t, q, qd) -> tau`` (NumPy in and out; or an object with ``__call__`` and ``reset``,
    reset before the run) at every control step, t = k·dt. Its torque then goes through the motors,
    their limits and the plant exactly as the PD's does in ``run``, and the recordings are run's.
    ``flags`` are run's (``duration=``, ``motors=``, ``q0=``, ``rrd=``, ``mcap=``, …). A controller that
    raises, or returns the wrong length or a value that is not finite, stops the run there (its
    recordings end whole) and raises ArmscopeError with the step's time; what it raised is the
    cause."""
    urdf = model.urdf if isinstance(model, Model) else model
    return _run(_argv({"urdf": urdf, **flags}), controller)


def _run(argv, controller=None) -> Run:
    """The binding's run of ``argv`` (with ``controller`` in the PD's place where given) as a Run."""
    arrays = _armscope.run(argv, controller)
    return Run(arrays, json.loads(arrays.pop("summary_json")))


class Episode:
    """One recorded episode replayed: ``episode`` (its index), ``t`` (N,), per joint (N, nq) the
    smoothed motion ``q``, ``qd``, ``qdd``, the torque it needed ``tau`` and what the joint had in that
    direction ``available``; ``verdicts``, per joint the dict ``replay --summary-json`` gives (peak and
    RMS torque, time over the limit, a servo's duty and protection, …)."""

    def __init__(self, d):
        self.episode = d["episode"]
        self.t, self.q, self.qd, self.qdd = d["t"], d["q"], d["qd"], d["qdd"]
        self.tau, self.available = d["tau"], d["available"]
        self.verdicts = json.loads(d["verdicts_json"])

    def __repr__(self):
        return f"armscope.Episode({self.episode}: {self.t.size} samples of {self.q.shape[1]} joints)"


def replay(source, urdf, **options) -> list:
    """``armscope replay SOURCE --urdf URDF``: every episode of a recorded motion (a LeRobot dataset, a
    ROS 2 bag, a CSV), read as the command reads it, replayed into the torque each joint needed.
    ``options``: ``motors``, ``payload``, ``tool``, ``episodes`` (a list), ``feature``, ``joint_map``,
    ``units`` ("degrees" or "range"), ``calibration``. Returns a list of :class:`Episode`; what the
    reading assumed comes as warnings."""
    return [Episode(d) for d in _armscope.replay(os.fspath(source), os.fspath(urdf), **options)]


def size(**flags) -> dict:
    """``armscope size`` with ``flags`` (its flags by name, ``-`` as ``_``): the dict its size.json
    holds (per joint the candidates, the chosen motor and ratio, the checks). Its table is printed
    as the command prints it; its files go to ``out=`` if given, else to a scratch folder removed
    after."""
    return json.loads(_armscope.size(_argv(flags)))


def batch(manifest=None, **flags) -> dict:
    """``armscope batch [MANIFEST]`` with ``flags``: the dict its summary.json holds (every
    experiment's status, error and summary; a failed experiment is in it, not raised). Its table is
    printed as the command prints it; its files go to ``out=`` if given, else to a scratch folder
    removed after."""
    argv = ([os.fspath(manifest)] if manifest is not None else []) + _argv(flags)
    return json.loads(_armscope.batch(argv))


def main() -> None:
    """The ``armscope`` command (``pip install armscope`` puts it on PATH)."""
    sys.exit(_main(sys.argv))
