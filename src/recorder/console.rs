use super::{Recorder, RunInfo, fmt_list, is_on_period};
use crate::error::Error;
use crate::sample::Sample;
use crate::summary::{RunStatus, Summary};
use std::io::Write;

/// The tutorial's console: a start line, one line per whole second (with `--debug`, the command,
/// error, τ_g and torque under it), and the summary.
pub struct Console {
    out: Box<dyn Write + Send>,
    dt: f64,
    debug: bool,
    err: Vec<f64>,
    closed: bool,
}

impl Console {
    pub fn new(out: Box<dyn Write + Send>) -> Self {
        Self { out, dt: 0.0, debug: false, err: Vec::new(), closed: false }
    }

    pub fn stdout() -> Self {
        Self::new(Box::new(std::io::stdout()))
    }
}

fn io(e: std::io::Error) -> Error {
    Error::Output { path: "console".into(), message: e.to_string() }
}

/// A closed pipe (`armscope run | head`) ends the console's output, not the run.
fn quiet_on_broken_pipe(result: Result<(), Error>, closed: &mut bool) -> Result<(), Error> {
    match result {
        Err(Error::Output { message, .. }) if message.contains("Broken pipe") => {
            *closed = true;
            Ok(())
        }
        other => other,
    }
}

impl Recorder for Console {
    fn start(&mut self, run: &RunInfo) -> Result<(), Error> {
        let result = self.write_start(run);
        quiet_on_broken_pipe(result, &mut self.closed)
    }

    fn record(&mut self, s: &Sample) -> Result<(), Error> {
        if self.closed || !is_on_period(s.k, self.dt, 1.0) {
            return Ok(());
        }
        let result = self.write_line(s);
        quiet_on_broken_pipe(result, &mut self.closed)
    }

    fn finish(&mut self, _run: &RunInfo, s: &Summary) -> Result<(), Error> {
        if self.closed {
            return Ok(());
        }
        let result = write_summary(&mut self.out, s).map_err(io);
        quiet_on_broken_pipe(result, &mut self.closed)
    }
}

impl Console {
    fn write_start(&mut self, run: &RunInfo) -> Result<(), Error> {
        let e = run.experiment;
        let m = &e.model;
        self.dt = e.config.dt;
        self.debug = e.config.debug;
        let g = m.gravity;
        writeln!(
            self.out,
            "armscope: {} ({}), {} dof, gravity ({}, {}, {}) m/s², tool link '{}'",
            m.name,
            m.source.display(),
            m.dof(),
            g.x,
            g.y,
            g.z,
            m.frames[m.tool_frame].name
        )
        .map_err(io)?;
        writeln!(self.out, "  plant: {}", run.plant).map_err(io)?;
        if let Some(motors) = &e.motors {
            let names: Vec<String> = m.joints.iter().map(|j| j.name.clone()).collect();
            let mode = if e.stepper_mode() { "; stepper joints driven open loop in microsteps (no PD; --drive pd for the PD controller)" } else { "" };
            writeln!(self.out, "  motors ({}): the torque limit falls with the joint's speed{mode}", motors.source.display()).map_err(io)?;
            write!(self.out, "{}", motors.table(&names)).map_err(io)?;
            if let Some(servos) = &e.servos {
                writeln!(self.out, "  servos driven by their own firmware (no PD; --drive pd for the PD controller on their datasheet line):").map_err(io)?;
                for (j, servo, ratio) in servos.servos() {
                    let behind = if ratio != 1.0 { format!(", behind a {ratio}:1 reduction") } else { String::new() };
                    writeln!(self.out, "    {}: {}{behind}; duty saturates beyond {:.3} rad of error", m.joints[j].name, crate::actuator::Motor::describe(servo), servo.firmware.saturation_error() / ratio).map_err(io)?;
                }
            }
        }
        writeln!(self.out, "  command: {}", run.trajectory).map_err(io)?;
        if e.gains.drives_a_joint() {
            writeln!(
                self.out,
                "  controller: PD{} every {} ms, gains ({}): kp = {:?}, kd = {:?}",
                if e.config.no_ff { " without gravity feed-forward (--no-ff)" } else { " + gravity feed-forward" },
                e.config.dt * 1e3,
                e.gains.source,
                e.gains.kp,
                e.gains.kd
            )
            .map_err(io)?;
        } else {
            writeln!(self.out, "  controller: none (the PD drives no joint: each is driven by its servo's firmware or an open-loop stepper), commands every {} ms", e.config.dt * 1e3).map_err(io)?;
        }
        if let Some(inertia) = &e.gains.effective_inertia {
            let radius = e.gains.spectral_radius.map_or(String::new(), |r| format!(", worst spectral radius of the sampled loop along the command {r:.3}"));
            writeln!(self.out, "  auto-tuned gains (kp = min(effort/0.05, I·ω² + D·ω), kd = 2·ζ·√(kp·I), I = smallest M_ii along the command, ω = 0.1/dt and ζ = 1 lowered for the joints of each mode of the sampled loop unstable with twice the gains{radius}):").map_err(io)?;
            let w = m.joints.iter().map(|j| j.name.chars().count() + 1).max().unwrap_or(0).max(8);
            writeln!(self.out, "    {:<w$}{:>14}{:>12}{:>8}{:>12}{:>12}", "joint", "I (kg·m²)", "ω (rad/s)", "ζ", "kp", "kd").map_err(io)?;
            let (omega, zeta) = (e.gains.bandwidth.as_deref().unwrap_or(&[]), e.gains.damping_ratio.as_deref().unwrap_or(&[]));
            for (j, joint) in m.joints.iter().enumerate() {
                let (w_j, z_j) = (omega.get(j).copied().unwrap_or(f64::NAN), zeta.get(j).copied().unwrap_or(f64::NAN));
                writeln!(self.out, "    {:<w$}{:>14.4e}{:>12.1}{:>8.2}{:>12.4}{:>12.5}", joint.name, inertia[j], w_j, z_j, e.gains.kp[j], e.gains.kd[j]).map_err(io)?;
            }
        }
        writeln!(self.out, "  duration {} s ({} steps)", e.config.duration, e.steps).map_err(io)?;
        Ok(())
    }

    fn write_line(&mut self, s: &Sample) -> Result<(), Error> {
        let p = s.tool_position;
        writeln!(self.out, "t = {:6.2} s  q = {} rad  tool = ({:.4}, {:.4}, {:.4}) m", s.t, fmt_list(s.q, 4), p.x, p.y, p.z)
            .map_err(io)?;
        if self.debug {
            self.err.clear();
            self.err.extend(s.cmd.iter().zip(s.q).map(|(c, q)| c - q));
            writeln!(self.out, "    cmd   = {}", fmt_list(s.cmd, 4)).map_err(io)?;
            writeln!(self.out, "    error = {}", fmt_list(&self.err, 4)).map_err(io)?;
            writeln!(self.out, "    tau_g = {}", fmt_list(s.tau_g, 4)).map_err(io)?;
            writeln!(self.out, "    u     = {}", fmt_list(s.u, 4)).map_err(io)?;
        }
        Ok(())
    }
}

/// The console summary (also used by `batch`).
pub fn write_summary(out: &mut dyn Write, s: &Summary) -> std::io::Result<()> {
    writeln!(out)?;
    match &s.status {
        RunStatus::Completed => {}
        RunStatus::Interrupted { time } => writeln!(out, "INTERRUPTED at t = {time:.3} s: the summary covers the run up to there")?,
        RunStatus::Diverged { message, .. } => writeln!(out, "DIVERGED: {message}")?,
        RunStatus::Collided { time, link1, link2 } => writeln!(out, "STOPPED at the first collision, t = {time:.3} s: {link1} with {link2} (--stop-on-collision); the summary covers the run up to there")?,
    }
    let speed = if s.wall_time > 0.0 { s.simulated_time / s.wall_time } else { f64::INFINITY };
    writeln!(
        out,
        "Summary: {:.3} s simulated in {} steps, {:.3} s wall time ({:.0}x real time)",
        s.simulated_time, s.steps, s.wall_time, speed
    )?;
    // columns as wide as the longest joint name (UR5's `shoulder_lift_joint`), at least 9
    let w = s.joints.iter().map(|n| n.chars().count() + 1).max().unwrap_or(0).max(9);
    let row = |label: &str, cells: Vec<String>| format!("  {label:<22}{}", cells.iter().map(|c| format!("{c:>w$}")).collect::<String>());
    writeln!(out, "{}", row("joint", s.joints.clone()))?;
    let opt = |v: &Option<f64>| v.map_or("n/a".to_string(), |x| format!("{x:.4}"));
    writeln!(
        out,
        "{}   (every step with t >= {} s)",
        row("max |error| (rad)", s.max_abs_error.iter().map(opt).collect()),
        s.error_window_start
    )?;
    writeln!(out, "{}", row("RMS error (rad)", s.rms_error.iter().map(opt).collect()))?;
    writeln!(out, "{}", row("saturation (%)", s.saturation_percent.iter().map(|p| format!("{p:.1}")).collect()))?;
    writeln!(out, "{}", row("chatter (%)", s.chatter_percent.iter().map(|p| format!("{p:.1}")).collect()))?;
    writeln!(out, "{}", row("peak |u| (N·m)", s.peak_abs_torque.iter().map(|p| format!("{p:.3}")).collect()))?;
    if s.peak_abs_torque_after_settle.iter().any(|p| p.is_some()) {
        writeln!(out, "{}   (t >= {} s: the motion's own)", row("  after settling", s.peak_abs_torque_after_settle.iter().map(|p| p.map_or("n/a".into(), |p| format!("{p:.3}"))).collect()), s.error_window_start)?;
    }
    writeln!(out, "{}", row("RMS |u| (N·m)", s.rms_torque.iter().map(|p| format!("{p:.3}")).collect()))?;
    let share = |x: Option<f64>, of: f64| x.map_or("-".to_string(), |r| format!("{:.0}", 100.0 * of / r));
    if s.drive_duty.iter().flatten().any(|d| d.continuous_torque.is_some()) {
        writeln!(out, "{}   (the motor's RMS torque at its shaft, u/N, over its continuous rating)", row("RMS of cont. (%)", s.drive_duty.iter().map(|d| d.as_ref().map_or("-".into(), |d| share(d.continuous_torque, d.rms_motor_torque))).collect()))?;
    }
    if s.drive_duty.iter().flatten().any(|d| d.rated_average_torque.is_some()) {
        writeln!(out, "{}   (the cubic mean of |u| through the gearbox over its rated average torque)", row("gear avg of rated (%)", s.drive_duty.iter().map(|d| d.as_ref().map_or("-".into(), |d| share(d.rated_average_torque, d.cubic_mean_torque))).collect()))?;
    }
    if s.winding.iter().any(Option::is_some) {
        let cell = |f: &dyn Fn(&crate::actuator::thermal::WindingSummary) -> String| s.winding.iter().map(|w| w.as_ref().map_or("-".to_string(), f)).collect::<Vec<_>>();
        writeln!(out, "{}", row("winding peak (°C)", cell(&|w| format!("{:.1}", w.peak_temperature))))?;
        writeln!(out, "{}   (at the run's RMS current, 25 °C ambient)", row("  steady / limit (°C)", cell(&|w| format!("{}/{:.0}", w.steady_temperature.map_or("runaway".into(), |t| format!("{t:.0}")), w.max_temperature))))?;
        writeln!(out, "{}   (going on at the run's RMS current)", row("  limit reached in", cell(&|w| w.time_to_limit.map_or("never".into(), |t| if t == 0.0 { "reached".into() } else { format!("{t:.0} s") }))))?;
        let unchecked: Vec<&str> = s.joints.iter().zip(&s.winding).filter(|(_, w)| w.is_none()).map(|(j, _)| j.as_str()).collect();
        if !unchecked.is_empty() {
            writeln!(out, "  not thermally checked (no thermal data for their motors): {}", unchecked.join(", "))?;
        }
    }
    if let Some(c) = &s.collisions {
        match &c.first_contact {
            None => writeln!(out, "  collisions: none ({} checked)", c.checked)?,
            Some((t, a, b)) => writeln!(out, "  collisions: first at t = {t:.3} s, {a} with {b}; {} control steps in contact ({} checked)", c.steps_in_contact, c.checked)?,
        }
        for p in c.pairs.iter().take(8) {
            let what = if p.steps_in_contact > 0 { format!("in contact {} steps, deepest {:.1} mm", p.steps_in_contact, -1e3 * p.closest) } else { format!("closest {:.1} mm", 1e3 * p.closest) };
            writeln!(out, "    {} — {}: {what} at t = {:.3} s", p.link1, p.link2, p.closest_at)?;
        }
        if c.pairs.len() > 8 {
            writeln!(out, "    … and {} more pairs closer than 5 cm (the summary JSON lists them)", c.pairs.len() - 8)?;
        }
    }
    if s.servos.iter().any(Option::is_some) {
        let cell = |f: &dyn Fn(&crate::summary::ServoDuty) -> String| s.servos.iter().map(|d| d.as_ref().map_or("-".to_string(), f)).collect::<Vec<_>>();
        writeln!(out, "{}   (the servo's PWM at its limit)", row("full duty (%)", cell(&|d| format!("{:.1}", d.full_duty_percent))))?;
        writeln!(out, "{}", row("peak current (A)", cell(&|d| format!("{:.2}", d.peak_current))))?;
        writeln!(out, "{}", row("RMS current (A)", cell(&|d| format!("{:.2}", d.rms_current))))?;
    }
    if !s.stuck_percent.is_empty() {
        writeln!(out, "{}", row("peak friction (N·m)", s.peak_friction_torque.iter().map(|p| format!("{p:.3}")).collect()))?;
        writeln!(out, "{}", row("stuck (%)", s.stuck_percent.iter().map(|p| format!("{p:.1}")).collect()))?;
    }
    writeln!(out, "{}", row("effort limit (N·m)", s.effort_limit.iter().map(|p| format!("{}", (p * 1e3).round() / 1e3)).collect()))?;
    if s.first_lost_step_time.iter().any(|t| t.is_some()) || s.lost_steps.iter().any(|&l| l > 0) {
        writeln!(out, "{}", row("lost steps (full)", s.lost_steps.iter().map(|p| format!("{p}")).collect()))?;
    }
    if s.lowest_torque_limit.iter().zip(&s.effort_limit).any(|(a, b)| a != b) {
        writeln!(out, "{}", row("lowest limit (N·m)", s.lowest_torque_limit.iter().map(|p| format!("{p:.3}")).collect()))?;
    }
    writeln!(out, "{}", row("limit hits (steps)", s.limit_hits.iter().map(|p| format!("{p}")).collect()))?;
    let r = &s.tool_range;
    writeln!(
        out,
        "  tool range: x [{:.3}, {:.3}]  y [{:.3}, {:.3}]  z [{:.3}, {:.3}] m",
        r.x.min, r.x.max, r.y.min, r.y.max, r.z.min, r.z.max
    )?;
    for verdict in s.saturation_verdicts() {
        writeln!(out, "  {verdict}")?;
    }
    out.flush()
}
