//! What `armscope size` shows: the console and Markdown table, the motor file of the choice, and per
//! joint a chart of motor × ratio with the feasible region and the choice marked.

use super::screening::{BillRow, Candidate, JointSizing, SizeReport};
use crate::canvas::{Canvas, ratio_color};

/// A headroom factor for people: 2.4×, 37×, ∞.
fn times(x: f64) -> String {
    if !x.is_finite() {
        "∞".into()
    } else if x >= 10.0 {
        format!("{x:.0}×")
    } else {
        format!("{x:.2}×")
    }
}

fn ratio_text(r: f64) -> String {
    if r.fract() == 0.0 { format!("{r:.0}") } else { format!("{r:.4}").trim_end_matches('0').to_string() }
}

impl Candidate {
    /// The drive train in words: "17HS4401 + NPS015 at 5:1", "17HS4401 at 12:1", "XM430-W350 (direct)".
    pub fn drive_name(&self) -> String {
        match (&self.reduction, self.ratio) {
            (Some(r), ratio) => format!("{} + {r} at {}:1", self.motor, ratio_text(ratio)),
            (None, ratio) => format!("{} at {}:1", self.motor, ratio_text(ratio)),
        }
    }
}

impl JointSizing {
    /// The last simulation of candidate `c`, in words.
    fn simulation(&self, c: usize) -> Option<String> {
        self.simulated.iter().rev().find(|s| s.candidate == c).map(|s| match &s.note {
            None if s.stepped => format!("0 lost steps, {:.0} % of its torque", 100.0 * s.peak_torque_share),
            None => format!("{:.0} % of its torque", 100.0 * s.peak_torque_share),
            Some(note) => note.clone(),
        })
    }

    fn describe(&self, c: usize) -> String {
        let x = &self.candidates[c];
        let sim = self.simulation(c).map_or(String::new(), |s| format!(", simulated: {s}"));
        let fit = match &x.shortfall {
            None => format!("{} the torque, {} the speed needed", times(x.torque_headroom), times(x.speed_headroom)),
            Some(s) => s.describe(),
        };
        format!("{} ({:.2} N·m at rest, {:.3} kg, {fit}{sim})", x.drive_name(), x.torque_at_rest, x.mass_kg)
    }

    /// The check that binds the chosen candidate: the one its share comes from on paper, or the
    /// full simulation's peak when that used more.
    fn binding(&self, c: &Candidate) -> &'static str {
        let simulated = self.chosen.and_then(|i| self.simulated.iter().rev().find(|s| s.candidate == i)).map_or(0.0, |s| s.peak_torque_share * (1.0 + c.margin));
        if simulated > c.share {
            return "peak torque in the full run";
        }
        c.binding.unwrap_or("peak torque on the curve")
    }

    fn candidate(&self, c: Option<usize>) -> Option<&Candidate> {
        c.map(|c| &self.candidates[c])
    }
}

impl SizeReport {
    /// The margins in words: "margin 30 %" (`--margin`) or the vendors' per kind.
    fn margin_text(&self) -> String {
        match self.margin {
            Some(m) => format!("margin {:.0} %", 100.0 * m),
            None => format!(
                "the vendors' margins ({}: Parker and MotionControlTips ask 50 % of an open-loop stepper, 10–30 % of a closed-loop servo; --margin sets one)",
                self.margins.iter().map(|(kind, m)| format!("{kind} {:.0} %", 100.0 * m)).collect::<Vec<_>>().join(", ")
            ),
        }
    }

    /// The bill of materials: per joint with a choice, its parts and how hard the motion uses them.
    pub fn bill_rows(&self) -> Vec<BillRow> {
        self.joints
            .iter()
            .filter_map(|js| {
                let c = js.candidate(js.chosen)?;
                let passed = js.chosen.and_then(|i| js.simulated.iter().rev().find(|s| s.candidate == i && s.passed));
                Some(BillRow {
                    joint: js.joint.clone(),
                    motor: c.motor.clone(),
                    reduction: c.reduction.clone(),
                    ratio: c.ratio,
                    mass_kg: c.mass_kg,
                    peak_use: passed.map(|s| s.peak_torque_share),
                    rms_motor_torque: c.rms_motor_torque,
                    rms_use: c.continuous_torque.map(|r| c.rms_motor_torque / r),
                    peak_winding_temperature: passed.and_then(|s| s.peak_winding_temperature),
                    peak_current: passed.and_then(|s| s.peak_current),
                    rms_current: passed.and_then(|s| s.rms_current),
                    inertia_ratio: c.inertia_ratio,
                    binding: js.binding(c).to_string(),
                })
            })
            .collect()
    }

    /// The bill of materials in Markdown: per joint the motor, its reduction and ratio, the masses,
    /// the use (peak and RMS), the peak winding temperature, the binding check; the total; what to buy.
    pub fn bill_of_materials(&self) -> String {
        let mut md = String::from("## Bill of materials\n\n| joint | motor | reduction | ratio | mass (kg) | peak use (full run) | RMS motor torque (N·m) | RMS of continuous | peak winding (°C) | inertia ratio | binding check |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
        let mut total = 0.0;
        let mut count: Vec<(String, usize)> = Vec::new();
        for (row, js) in self.bill_of_materials.iter().zip(self.joints.iter().filter(|js| js.chosen.is_some())) {
            total += row.mass_kg;
            for part in std::iter::once(row.motor.as_str()).chain(row.reduction.iter().flat_map(|r| r.split(" + "))) {
                match count.iter_mut().find(|(p, _)| p == part) {
                    Some((_, n)) => *n += 1,
                    None => count.push((part.to_string(), 1)),
                }
            }
            let percent = |x: Option<f64>| x.map_or("–".to_string(), |x| format!("{:.0} %", 100.0 * x));
            let ratio = row.inertia_ratio.map_or("n/p".to_string(), |r| format!("{r:.1}:1{}", if js.inertia_ratio_above.is_some() { " ⚠" } else { "" }));
            md += &format!(
                "| {} | {} | {} | {} | {:.3} | {} | {:.4} | {} | {} | {ratio} | {} |\n",
                row.joint,
                row.motor,
                row.reduction.as_deref().unwrap_or(if row.ratio == 1.0 { "direct" } else { "ideal" }),
                ratio_text(row.ratio),
                row.mass_kg,
                percent(row.peak_use),
                row.rms_motor_torque,
                percent(row.rms_use),
                row.peak_winding_temperature.map_or("–".to_string(), |t| format!("{t:.1}")),
                row.binding
            );
        }
        md += &format!("\nDrive trains: {total:.3} kg in all. To order: {}.\n", count.iter().map(|(p, n)| format!("{n} × {p}")).collect::<Vec<_>>().join(", "));
        let currents: Vec<String> = self.bill_of_materials.iter().filter_map(|r| Some(format!("{} {:.2} A peak, {:.2} A RMS", r.joint, r.peak_current?, r.rms_current?))).collect();
        if !currents.is_empty() {
            md += &format!("\nServo currents in the full run, driven by their firmware (what the supply must give, and what heats them): {}; at once, the supply gives up to their sum.\n", currents.join(", "));
        }
        let notes: Vec<String> = self
            .joints
            .iter()
            .filter_map(|js| {
                let c = js.candidate(js.chosen)?;
                let mut out = Vec::new();
                if let Some((guideline, whom)) = &js.inertia_ratio_above {
                    out.push(format!("{}: the load's inertia is {:.1}× the rotor's at the joint, above the {guideline:.0}:1 guideline for {whom}", js.joint, c.inertia_ratio.unwrap_or(0.0)));
                }
                if let Some(l) = js.lowest_rms.filter(|&l| Some(l) != js.chosen) {
                    let x = &js.candidates[l];
                    let optimum = js.optimal_ratio.map_or(String::new(), |n| format!("; on a pure inertia load the optimum would be N* = √(rms τ / (η·J·rms q̈)) = {n:.0}"));
                    out.push(format!("{}: the feasible drive of this motor with the lowest RMS motor torque is {} ({:.4} N·m against {:.4}{optimum})", js.joint, x.drive_name(), x.rms_motor_torque, c.rms_motor_torque));
                }
                Some(out)
            })
            .flatten()
            .collect();
        if !notes.is_empty() {
            md += &format!("\n{}\n", notes.iter().map(|n| format!("- {n}")).collect::<Vec<_>>().join("\n"));
        }
        md += "\nThe motor file: `motors.toml` (and `--motors-out`), for `armscope run --motors`.\n";
        md
    }

    /// Markdown: per joint the choice, the runner-up and why the nearest rejected ones fail.
    pub fn markdown(&self) -> String {
        let mut md = format!(
            "# Motor sizing for {}\n\nMotion: {}; payload {} kg at the tool; {} on torque and speed; {}; {} microsteps.\nCandidates: {}.\n\n",
            self.model,
            self.motions.join(", "),
            self.payload_kg,
            self.margin_text(),
            if self.reductions.is_empty() { format!("ideal reductions {:.0} % efficient", 100.0 * self.efficiency) } else { format!("reductions from the catalogue ({}) or a direct drive", self.reductions.join(", ")) },
            self.microsteps,
            self.motors.join(", ")
        );
        md += &if self.parts_in_urdf {
            format!("The drive trains are in the URDF's masses (--parts-in-urdf): nothing carried; the arm {:.3} kg, the chosen drive trains {:.3} kg of it.\n\n", self.arm_mass_kg, self.drive_mass_kg)
        } else {
            format!(
                "Each candidate's motor and reduction are carried on the arm (on the parent link of its joint, at the joint), each joint sized with the parts beyond it already chosen: the arm {:.3} kg without drive trains, {:.3} kg with the chosen ones ({:.3} kg).\n\n",
                self.arm_mass_kg,
                self.arm_mass_kg + self.drive_mass_kg,
                self.drive_mass_kg
            )
        };
        if !self.weightless_reductions.is_empty() {
            md += &format!("Reductions without a published mass, counted as weightless: {}.\n\n", self.weightless_reductions.join(", "));
        }
        md += &format!(
            "Duty checks (beside the peak torque on the curve): each motor's RMS torque with the margin against its continuous rating, and the winding of a motor with thermal data over {} at that RMS current, from 25 °C ambient.{}\n\n",
            if self.duty_seconds >= 3600.0 { format!("{} h", (self.duty_seconds / 3.6).round() / 1000.0) } else { format!("{:.0} s", self.duty_seconds) },
            if self.duty_unchecked.is_empty() { String::new() } else { format!(" Not duty-checked (no continuous rating, no thermal data in the catalogue): {}.", self.duty_unchecked.join(", ")) }
        );
        md += "| joint | motor | reduction | ratio | mass (kg) | at rest (N·m) | torque to spare | speed to spare | simulated | runner-up |\n|---|---|---|---|---|---|---|---|---|---|\n";
        for js in &self.joints {
            if js.candidates.is_empty() {
                continue;
            }
            let Some(c) = js.candidate(js.chosen) else {
                md += &format!("| {} | none fits | | | | | | | | |\n", js.joint);
                continue;
            };
            let sim = js.chosen.and_then(|c| js.simulation(c)).unwrap_or_else(|| "–".to_string());
            let runner = js.candidate(js.runner_up).map_or("–".to_string(), Candidate::drive_name);
            let top = js.candidates.iter().filter(|x| x.motor == c.motor).map(|x| x.ratio).fold(0.0, f64::max);
            let edge = if c.ratio == top { " (the largest tried)" } else { "" };
            let reduction = c.reduction.clone().unwrap_or_else(|| if c.ratio == 1.0 { "direct".into() } else { "ideal".into() });
            md += &format!("| {} | {} | {reduction} | {}{edge} | {:.3} | {:.2} | {} | {} | {sim} | {runner} |\n", js.joint, c.motor, ratio_text(c.ratio), c.mass_kg, c.torque_at_rest, times(c.torque_headroom), times(c.speed_headroom));
        }
        if let Some((experiment, t, a, b)) = &self.collision {
            md += &format!("\n**The motion collides**: {a} with {b} at t = {t:.2} s of '{experiment}' (its commanded path, checked every 10 ms): no valid sizing until the motion is changed.\n");
        }
        for (experiment, c) in &self.simulated_collisions {
            match &c.first_contact {
                Some((t, a, b)) => md += &format!("\n**The simulated arm collides** in '{experiment}': {a} with {b} at t = {t:.3} s, {} control steps in contact ({} checked): the chosen drives' tracking error takes it there; no valid sizing until the motion (or its clearance) is changed.\n", c.steps_in_contact, c.checked),
                None => {
                    let closest = c.pairs.first().map_or("none closer than 5 cm".to_string(), |p| format!("closest {} — {}, {:.1} mm at t = {:.2} s", p.link1, p.link2, 1e3 * p.closest, p.closest_at));
                    md += &format!("\nCollisions in the chosen set's simulation of '{experiment}': none ({}; {closest}).\n", c.checked);
                }
            }
        }
        md += &format!(
            "\n{} ({} simulation rounds, {} simulations).\n\nWhy not the nearest rejected candidates:\n\n",
            if self.verified { "The chosen set passed its full simulation, every joint at once" } else if self.collision.is_some() || self.simulated_collisions.iter().any(|(_, c)| c.first_contact.is_some()) { "The set was simulated, but the motion collides" } else { "**The chosen set did not pass its full simulation**" },
            self.rounds,
            self.simulations
        );
        for js in &self.joints {
            if js.candidates.is_empty() {
                continue;
            }
            if let Some(c) = js.chosen {
                md += &format!("- {}: chosen {}", js.joint, js.describe(c));
                if let Some(r) = js.runner_up {
                    md += &format!("; runner-up {}", js.describe(r));
                }
                md += "\n";
            } else {
                md += &format!("- {}: no candidate fits\n", js.joint);
            }
            for &r in &js.nearest_rejected {
                md += &format!("  - {}\n", js.describe(r));
            }
        }
        md += "\n";
        md += &self.bill_of_materials();
        md
    }

    /// The choice as a motor file for `armscope run --motors`.
    pub fn motor_file(&self, catalogue: Option<&str>) -> String {
        let mut toml = format!(
            "# Written by `armscope size` for {}: motion {}, payload {} kg, {}.\n# Each joint's motor and the reduction after it; run it with `armscope run --motors THIS_FILE`.\n",
            self.model,
            self.motions.join(", "),
            self.payload_kg,
            self.margin_text()
        );
        if let Some(path) = catalogue {
            toml += &format!("catalogue = {:?}\n", path);
        }
        toml += &format!("description = \"armscope size: payload {} kg\"\n", self.payload_kg);
        if self.parts_in_urdf {
            toml += "# sized with --parts-in-urdf: the URDF's masses hold the drive trains\nin_urdf = true\n";
        }
        for js in &self.joints {
            let Some(c) = js.candidate(js.chosen) else { continue };
            toml += &match &c.reduction {
                Some(_) if c.stages.len() > 1 => format!(
                    "\n[joints.{}]\nmotor = {:?}\nreduction = [{}]\ngear_ratio = [{}]\nmicrosteps = {}\n",
                    toml_key(&js.joint),
                    c.motor,
                    c.stages.iter().map(|(n, _)| format!("{n:?}")).collect::<Vec<_>>().join(", "),
                    c.stages.iter().map(|(_, r)| r.to_string()).collect::<Vec<_>>().join(", "),
                    self.microsteps
                ),
                Some(r) => format!("\n[joints.{}]\nmotor = {:?}\nreduction = {r:?}\ngear_ratio = {}\nmicrosteps = {}\n", toml_key(&js.joint), c.motor, c.ratio, self.microsteps),
                None => format!("\n[joints.{}]\nmotor = {:?}\ngear_ratio = {}\nefficiency = {}\nmicrosteps = {}\n", toml_key(&js.joint), c.motor, c.ratio, if c.ratio == 1.0 { 1.0 } else { self.efficiency }, self.microsteps),
            };
        }
        toml
    }

    /// Joint `j`'s chart: a cell per motor (rows, lightest at the bottom) and ratio (columns),
    /// coloured by need / available with the margin (red above 1: infeasible); the choice framed in
    /// black, the runner-up in grey.
    pub fn chart(&self, j: usize) -> Canvas {
        let js = &self.joints[j];
        let mut motors: Vec<&str> = Vec::new();
        for c in &js.candidates {
            if !motors.contains(&c.motor.as_str()) {
                motors.push(&c.motor);
            }
        }
        // columns: the drive options after the motor (reduction, ratio), by ratio
        let mut columns: Vec<(f64, Option<&str>)> = js.candidates.iter().map(|c| (c.ratio, c.reduction.as_deref())).collect();
        columns.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        columns.dedup();
        let ratios: Vec<f64> = columns.iter().map(|c| c.0).collect();
        let cw = (900 / ratios.len().max(1)).clamp(12, 64);
        let ch = (1400 / motors.len().max(1)).clamp(16, 40);
        let (left, bottom, top, right) = (230, 110, 70, 30);
        let (cols, rows) = (ratios.len(), motors.len());
        let legend = match js.candidate(js.chosen) {
            Some(c) => format!("BLACK FRAME: CHOSEN {}. GREY: RUNNER-UP. RED: INFEASIBLE (ABOVE 1). DOT: FAILED IN SIMULATION", c.drive_name().to_uppercase()),
            None => "NO CANDIDATE FITS. RED: INFEASIBLE (ABOVE 1). DOT: FAILED IN SIMULATION".to_string(),
        };
        let width = (left + cols * cw + right).max(Canvas::text_width(&legend, 2) + 16);
        let mut canvas = Canvas::new(width, top + rows * ch + bottom, [250, 250, 250]);
        let dark = [30, 30, 30];
        let title = format!("{}: NEED X (1 + MARGIN) / AVAILABLE{}", js.joint, if self.payload_kg > 0.0 { format!(", PAYLOAD {} KG", self.payload_kg) } else { String::new() });
        canvas.text(left.min(20), 18, &title, 3, dark);
        for (c, cand) in js.candidates.iter().enumerate() {
            let (Some(row), Some(col)) = (motors.iter().position(|m| *m == cand.motor), columns.iter().position(|c| c.0 == cand.ratio && c.1 == cand.reduction.as_deref())) else { continue };
            let (x, y) = (left + col * cw, top + (rows - 1 - row) * ch);
            let frame = if Some(c) == js.chosen { Some(dark) } else if Some(c) == js.runner_up { Some([120, 120, 120]) } else { None };
            match frame {
                Some(f) => {
                    canvas.fill(x.saturating_sub(3), y.saturating_sub(3), cw + 4, ch + 4, f);
                    canvas.fill(x + 2, y + 2, cw - 6, ch - 6, ratio_color(cand.share));
                }
                None => canvas.fill(x + 1, y + 1, cw - 4, ch - 4, ratio_color(cand.share)),
            }
            // feasible on the motion's inverse dynamics, but failed in the full simulation
            if cand.feasible() && Some(c) != js.chosen && js.simulated.iter().any(|s| s.candidate == c && !s.passed) && !js.simulated.iter().any(|s| s.candidate == c && s.passed) {
                let d = (cw / 3).max(4);
                canvas.fill(x + (cw - 2 - d) / 2, y + (ch - 2 - d) / 2, d, d, [110, 20, 20]);
            }
        }
        for (r, motor) in motors.iter().enumerate() {
            let y = top + (rows - 1 - r) * ch + ch / 2 - 5;
            canvas.text(left - 12 - Canvas::text_width(motor, 2), y, motor, 2, dark);
        }
        let every = ratios.len().div_ceil(18).max(1);
        for (col, ratio) in ratios.iter().enumerate() {
            if col % every == 0 || (col + 1 == ratios.len() && col % every >= every / 2 + 1) {
                let tick = ratio_text(*ratio);
                let x = (left + col * cw + cw / 2).saturating_sub(Canvas::text_width(&tick, 2) / 2);
                canvas.text(x, top + rows * ch + 8, &tick, 2, dark);
            }
        }
        let x_label = "GEAR RATIO AFTER THE MOTOR";
        canvas.text(left + (cols * cw).saturating_sub(Canvas::text_width(x_label, 2)) / 2, top + rows * ch + 36, x_label, 2, dark);
        canvas.text(8, top - 22, "MOTOR (LIGHTEST AT THE BOTTOM)", 2, dark);
        canvas.text(8, top + rows * ch + 70, &legend, 2, dark);
        canvas
    }
}

/// A TOML key: bare when it can be, quoted otherwise.
fn toml_key(name: &str) -> String {
    if !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') { name.to_string() } else { format!("{name:?}") }
}
