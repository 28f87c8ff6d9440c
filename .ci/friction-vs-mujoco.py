"""armscope's exact stiction against MuJoCo's `frictionloss` on one pendulum (1 kg at 0.5 m, Coulomb
friction F, no damping, 1 ms steps), and both against the energy balance:
  - released at 0.3 rad with F = 1.5 N·m (the weight's torque there, 1.45 N·m, is within F): how far
    it moves in 20 s;
  - released at 1.2 rad with F = 0.4 N·m: where it is after 15 s, against the angle where the
    energy balance brings it to rest (each half swing loses F × the angle swept).
armscope must not move in the first case and must rest within 1e-6 rad (continuous plant) / 1e-5 rad
(discrete) of the balance in the second; MuJoCo's numbers are printed for the README (its friction
is a soft constraint: it creeps). Usage: python friction-vs-mujoco.py ARMSCOPE"""
import math, os, subprocess, sys, tempfile
import mujoco
import numpy as np

MASS, LENGTH, G = 1.0, 0.5, 9.81
MGL = MASS * G * LENGTH


def urdf(friction):
    return f"""<robot name="pendulum"><link name="world"/>
  <link name="bob"><inertial><origin xyz="0 0 -{LENGTH}"/><mass value="{MASS}"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="swing" type="continuous"><parent link="world"/><child link="bob"/><axis xyz="0 1 0"/>
    <limit effort="10" velocity="10"/><dynamics damping="0" friction="{friction}"/></joint></robot>"""


def armscope(exe, friction, angle, seconds, continuous):
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "pendulum.urdf")
        open(path, "w").write(urdf(friction))
        extra = ["--time-step", "0", "--rtol", "1e-11", "--atol", "1e-13"] if continuous else []
        subprocess.run([exe, "run", "--urdf", path, "--static", "--kp", "0", "--kd", "0", "--no-ff", "--q0", f"swing={angle!r}",
                        "--duration", str(seconds), "--quiet", "--no-rrd", "--no-mcap", "--trace", "t.csv", *extra], check=True, cwd=d, capture_output=True)
        return np.loadtxt(os.path.join(d, "t.csv"), delimiter=",", skiprows=1)[:, 1]


def mujoco_run(friction, angle, seconds):
    xml = f"""<mujoco><option timestep="0.001" integrator="Euler" gravity="0 0 -{G}"/><worldbody><body>
      <joint type="hinge" axis="0 1 0" frictionloss="{friction}" damping="0"/>
      <inertial pos="0 0 -{LENGTH}" mass="{MASS}" diaginertia="1e-4 1e-4 1e-4"/></body></worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.qpos[0] = angle
    q = [angle]
    for _ in range(round(seconds / 0.001)):
        mujoco.mj_step(m, d)
        q.append(d.qpos[0])
    return np.array(q)


def rest_angle(friction, angle):
    a = angle
    while MGL * abs(math.sin(a)) > friction:
        sign, start = math.copysign(1.0, a), abs(a)
        lo, hi = -start, math.asin(friction / MGL)
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if MGL * (math.cos(mid) - math.cos(start)) - friction * (start - mid) < 0 else (lo, mid)
        a = sign * 0.5 * (lo + hi)
    return a


def main():
    exe = os.path.abspath(sys.argv[1])
    failures = []
    print(f"MuJoCo {mujoco.__version__} frictionloss (default solref/solimp, Euler, 1 ms) against armscope's exact stiction")
    for name, q in [("armscope discrete", armscope(exe, 1.5, 0.3, 20, False)), ("armscope continuous", armscope(exe, 1.5, 0.3, 20, True)), ("MuJoCo", mujoco_run(1.5, 0.3, 20))]:
        drift = np.abs(q - 0.3).max()
        print(f"  held (0.3 rad, weight 1.450 N·m within F = 1.5): {name:20s} moved up to {drift:.3e} rad in 20 s, {abs(q[-1] - q[-1001]):.2e} rad in the last second")
        if name.startswith("armscope") and drift != 0.0:
            failures.append(f"{name} moved {drift:e} rad while held by friction")
    expected = rest_angle(0.4, 1.2)
    for name, q, bound in [("armscope discrete", armscope(exe, 0.4, 1.2, 15, False), 1e-5), ("armscope continuous", armscope(exe, 0.4, 1.2, 15, True), 1e-6), ("MuJoCo", mujoco_run(0.4, 1.2, 15), None)]:
        off = q[-1] - expected
        print(f"  released (1.2 rad, F = 0.4): {name:20s} at 15 s {q[-1]:.9f} rad, {off:+.2e} from the energy balance's rest {expected:.9f}, {abs(q[-1] - q[-1001]):.2e} rad in the last second")
        if bound is not None and not abs(off) <= bound:
            failures.append(f"{name} rests {off:e} rad from the energy balance")
    if failures:
        print("friction check FAILED:\n  " + "\n  ".join(failures))
        sys.exit(1)


if __name__ == "__main__":
    main()
