//! The run's configuration and summary as Markdown documents in the recording.

use crate::recorder::RunInfo;
use crate::summary::Summary;

/// The run's configuration as Markdown, for the recording.
pub fn config_markdown(run: &RunInfo) -> String {
    let e = run.experiment;
    let m = &e.model;
    format!(
        "# armscope run\n\n* model: **{}** (`{}`), {} dof, gravity ({}, {}, {}) m/s²\n* plant: {}\n* command: {}\n* controller: {}, control period {} ms\n* gains ({}): kp = {:?}, kd = {:?}\n* duration: {} s ({} steps)\n{}\n```json\n{}\n```\n",
        m.name,
        m.source.display(),
        m.dof(),
        m.gravity.x,
        m.gravity.y,
        m.gravity.z,
        run.plant,
        run.trajectory,
        if !e.gains.drives_a_joint() {
            "none (each joint's servo firmware or stepper)"
        } else if e.config.no_ff {
            "PD without gravity feed-forward"
        } else {
            "PD + gravity feed-forward"
        },
        e.config.dt * 1e3,
        e.gains.source,
        e.gains.kp,
        e.gains.kd,
        e.config.duration,
        e.steps,
        // what armscope assumed on the user's behalf (a welded root, a moved start pose, …)
        m.notices.iter().map(|n| format!("* notice: {n}\n")).collect::<String>(),
        serde_json::to_string_pretty(&e.config).unwrap_or_default()
    )
}

pub fn summary_markdown(summary: &Summary) -> String {
    let mut text = Vec::new();
    let _ = crate::recorder::console::write_summary(&mut text, summary);
    format!("# summary\n\n```\n{}\n```\n\n```json\n{}\n```\n", String::from_utf8_lossy(&text).trim(), serde_json::to_string_pretty(summary).unwrap_or_default())
}
