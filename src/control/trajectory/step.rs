use super::Trajectory;

/// `--test-joint N`: a step of `angle` on one joint at t = 0, every other joint held at 0.
#[derive(Clone, Debug)]
pub struct JointStep {
    pub joint: usize,
    pub joint_name: String,
    pub angle: f64,
}

impl Trajectory for JointStep {
    fn sample(&self, _t: f64, cmd: &mut [f64], cmd_dot: &mut [f64]) {
        cmd.fill(0.0);
        cmd_dot.fill(0.0);
        cmd[self.joint] = self.angle;
    }

    fn describe(&self) -> String {
        format!("step test: {} (joint {}) to {} rad at t = 0, others held at 0", self.joint_name, self.joint + 1, self.angle)
    }
}
