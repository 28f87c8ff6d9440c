//! What a replay found, for people (a table and sentences per episode) and for programs (JSON).

use super::inverse::SmoothingInfo;
use super::verdict::JointVerdict;
use super::{EpisodeReplay, Replayer};
use serde::Serialize;

/// One episode's findings without its series (what a batch over a dataset keeps).
#[derive(Clone, Debug, Serialize)]
pub struct EpisodeSummary {
    pub label: String,
    pub index: Option<i64>,
    pub duration: f64,
    pub samples: usize,
    /// The largest |needed| / available of any joint, and which joint.
    pub peak_load: f64,
    pub worst_joint: String,
    pub joints: Vec<JointVerdict>,
    pub smoothing: Vec<Option<SmoothingInfo>>,
    /// Per joint with a measured effort: RMS and largest |measured − model|, N·m.
    pub measured_vs_model: Vec<Option<EffortGap>>,
    pub notices: Vec<String>,
    /// Where its positions passed a joint's URDF limit (said once for the recording).
    pub past_limits: Vec<super::past_limits::PastLimit>,
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct EffortGap {
    pub rms: f64,
    pub max: f64,
}

impl EpisodeSummary {
    pub fn of(replay: &EpisodeReplay, index: Option<i64>) -> Self {
        let m = &replay.motion;
        let loads: Vec<f64> = m.needed.iter().zip(&replay.available).map(|(needed, available)| super::verdict::peak_load(needed, available)).collect();
        let worst = loads.iter().enumerate().fold((0, 0.0_f64), |(bi, b), (i, &l)| if l > b { (i, l) } else { (bi, b) });
        let measured_vs_model = m
            .measured
            .iter()
            .zip(&m.needed)
            .map(|(measured, needed)| {
                let measured = measured.as_ref()?;
                let gaps: Vec<f64> = measured.iter().zip(needed).map(|(a, b)| a - b).filter(|d| d.is_finite()).collect();
                (!gaps.is_empty()).then(|| EffortGap { rms: (gaps.iter().map(|d| d * d).sum::<f64>() / gaps.len() as f64).sqrt(), max: gaps.iter().fold(0.0, |a: f64, d| a.max(d.abs())) })
            })
            .collect();
        Self {
            label: m.label.clone(),
            index,
            duration: m.time.last().copied().unwrap_or(0.0),
            samples: m.len(),
            peak_load: worst.1,
            worst_joint: replay.verdicts.get(worst.0).map(|v| v.joint.clone()).unwrap_or_default(),
            joints: replay.verdicts.clone(),
            smoothing: m.smoothing.clone(),
            measured_vs_model,
            notices: m.notices.clone(),
            past_limits: m.past_limits.clone(),
        }
    }

    /// Whether some joint needed more than it had.
    pub fn overloaded(&self) -> bool {
        self.joints.iter().any(|j| !j.over.is_empty())
    }
}

fn number(x: f64, decimals: usize) -> String {
    if x.is_finite() { format!("{x:.decimals$}") } else { "–".into() }
}

/// The table and the sentences of one episode.
pub fn episode_text(replayer: &Replayer, s: &EpisodeSummary) -> String {
    let rate = if s.duration > 0.0 { (s.samples - 1) as f64 / s.duration } else { 0.0 };
    let cutoffs: Vec<f64> = s.smoothing.iter().flatten().map(|i| i.cutoff_hz).collect();
    let (lo, hi) = cutoffs.iter().fold((f64::INFINITY, 0.0_f64), |(a, b), &c| (a.min(c), b.max(c)));
    let mut out = format!("{}: {:.2} s, {} samples at {:.1} Hz", s.label, s.duration, s.samples, rate);
    if !cutoffs.is_empty() {
        out += &format!(", smoothed to {}–{} Hz", number(lo, 1), number(hi, 1));
    }
    out += "\n";
    let w = s.joints.iter().map(|j| j.joint.chars().count()).max().unwrap_or(5).max(5) + 2;
    // a servo's duty (of its PWM) and current, where a joint has a servo model
    let servos = s.joints.iter().any(|j| j.servo.is_some());
    let servo_header = if servos { format!("{:>8}{:>8}", "duty %", "peak A") } else { String::new() };
    out += &format!("  {:<w$}{:>10}{:>8}{:>10}{:>9}{:>11}{:>9}{servo_header}  {}\n", "joint", "peak N·m", "at s", "had N·m", "RMS N·m", "cont. N·m", "°C peak", "limit");
    for j in &s.joints {
        let winding = j.winding.map_or("–".to_string(), |w| format!("{:.0}", w.peak_temperature));
        let servo = match (servos, &j.servo) {
            (false, _) => String::new(),
            (true, Some(l)) => format!("{:>8.0}{:>8.2}", 100.0 * l.peak_duty, l.peak_current),
            (true, None) => format!("{:>8}{:>8}", "–", "–"),
        };
        out += &format!("  {:<w$}{:>10}{:>8}{:>10}{:>9}{:>11}{:>9}{servo}  {}\n", j.joint, number(j.peak_torque, 3), number(j.peak_time, 2), number(j.limit_at_peak, 3), number(j.rms_torque, 3), j.continuous_torque.map_or("–".into(), |c| number(c, 3)), winding, j.limit_source);
    }
    for j in &s.joints {
        out += &joint_sentences(j);
    }
    if !s.overloaded() {
        out += &format!("  every joint had what it needed (the most loaded, {}, at {:.0} % of what it had)\n", s.worst_joint, 100.0 * s.peak_load);
    }
    for (j, gap) in s.measured_vs_model.iter().enumerate() {
        if let Some(g) = gap {
            out += &format!("  {}: measured effort − model torque: RMS {:.3} N·m, at most {:.3} N·m\n", replayer.model.joints[j].name, g.rms, g.max);
        }
    }
    out
}

/// Said as a person would: which joint, how much over, how long, from when.
fn joint_sentences(j: &JointVerdict) -> String {
    let mut out = String::new();
    if let Some(trip) = j.servo.and_then(|l| l.protection_trip) {
        out += &format!("  {}: {} — a real one reports an {} error; from then on it had only that\n", j.joint, trip.describe(), trip.kind.name());
    }
    let what = if j.limit_source == "URDF effort" { "its URDF effort limit".to_string() } else { format!("its {} gives", j.limit_source) };
    let shown = 3;
    for i in j.over.iter().take(shown) {
        let span = if i.first == i.last { format!("at {:.2} s (one sample)", i.start) } else { format!("from {:.2} s to {:.2} s ({:.2} s)", i.start, i.end, i.duration()) };
        out += &format!("  {} needed more than {what} {span}: at worst {:.3} N·m ({}) over, at {:.2} s\n", j.joint, i.worst_excess, percent_over(i.worst_percent), i.worst_time);
    }
    if j.over.len() > shown {
        out += &format!("  {} … and {} more times; {:.2} s over in all\n", j.joint, j.over.len() - shown, j.time_over);
    }
    if let Some(c) = j.continuous_torque
        && j.rms_torque > c
    {
        out += &format!("  {} needed {:.3} N·m RMS, above its motor's continuous {:.3} N·m ({:.0} %)\n", j.joint, j.rms_torque, c, 100.0 * j.rms_torque / c);
    }
    if let Some(w) = j.winding
        && w.peak_temperature >= w.max_temperature
    {
        out += &format!("  {}'s winding reached {:.0} °C, its limit is {:.0} °C\n", j.joint, w.peak_temperature, w.max_temperature);
    }
    out
}

/// A load (needed / had) as the ranking shows it: a percentage, or, where the joint needed torque at
/// a speed its motor gives none at, those words (a division by nothing is no number to print).
fn load_cell(load: f64) -> String {
    if load.is_finite() { format!("{:.0}%", 100.0 * load) } else { "too fast".into() }
}

/// A shortfall as a percentage of what the joint had, or, where it had nothing at that speed, why.
fn percent_over(percent: f64) -> String {
    if percent.is_finite() { format!("{percent:.0} %") } else { "at a speed its motor gives no torque at".into() }
}

/// How many episodes the ranking lists.
const RANKED: usize = 20;

/// A dataset's episodes, worst first: one line each (the most loaded [`RANKED`]).
pub fn ranking_text(summaries: &[EpisodeSummary]) -> String {
    let mut out = format!("{} episodes, the most loaded first (load: the largest needed/had of any joint; too fast: it needed torque at a speed past its motor's no-load speed):\n", summaries.len());
    let w = summaries.iter().map(|s| s.label.chars().count()).max().unwrap_or(7).max(7) + 2;
    out += &format!("  {:<w$}{:>8}  {:<16}{}\n", "episode", "load", "joint", "over");
    for s in summaries.iter().take(RANKED) {
        let over: Vec<String> = s.joints.iter().filter(|j| !j.over.is_empty()).map(|j| format!("{} {:.2} s", j.joint, j.time_over)).collect();
        out += &format!("  {:<w$}{:>8}  {:<16}{}\n", s.label, load_cell(s.peak_load), s.worst_joint, if over.is_empty() { "–".into() } else { over.join(", ") });
    }
    if summaries.len() > RANKED {
        let overloaded = summaries.iter().filter(|s| s.overloaded()).count();
        out += &format!("  … {} more (every episode in --summary-json); {overloaded} of the {} overloaded some joint\n", summaries.len() - RANKED, summaries.len());
    }
    out
}

/// The JSON document of `--summary-json`.
pub fn summary_json(replayer: &Replayer, source: &str, summaries: &[EpisodeSummary]) -> serde_json::Value {
    serde_json::json!({
        "source": source,
        "model": replayer.model.name,
        "urdf": replayer.model.source,
        "joints": replayer.model.joints.iter().map(|j| j.name.clone()).collect::<Vec<_>>(),
        "joint_map": replayer.map.source,
        "payload": replayer.experiment.config.payload,
        "motors": replayer.experiment.config.motors,
        "notices": replayer.model.notices,
        "episodes": summaries,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_joint_that_needed_torque_past_its_motors_speed_is_said_in_words() {
        // needed/available with nothing available is infinite: never printed as a number
        let summary = |label: &str, load: f64| EpisodeSummary { label: label.into(), index: None, duration: 1.0, samples: 30, peak_load: load, worst_joint: "elbow_flex".into(), joints: Vec::new(), smoothing: Vec::new(), measured_vs_model: Vec::new(), notices: Vec::new(), past_limits: Vec::new() };
        let text = ranking_text(&[summary("episode 0", f64::INFINITY), summary("episode 1", 0.42)]);
        assert!(text.contains("too fast") && text.contains("42%"), "{text}");
        assert!(!text.contains("inf") && !text.contains("NaN"), "{text}");
        assert_eq!(percent_over(f64::INFINITY), "at a speed its motor gives no torque at");
        assert_eq!(percent_over(12.4), "12 %");
    }
}
