use super::Trajectory;

/// `--static`: hold every joint at 0 (the start pose).
#[derive(Clone, Debug, Default)]
pub struct Hold;

impl Trajectory for Hold {
    fn sample(&self, _t: f64, cmd: &mut [f64], cmd_dot: &mut [f64]) {
        cmd.fill(0.0);
        cmd_dot.fill(0.0);
    }

    fn describe(&self) -> String {
        "static: hold every joint at 0".into()
    }
}
