//! A testbench's recordings: per log, the measured and simulated position (with the goal), PWM
//! duty, supply voltage and the simulated current, on one timeline from the log's start.
//! The `.rrd` opens to one row of plots per log; the `.mcap` has a JSON channel per log
//! (`/testbench/LOG`) that Foxglove's Plot panel reads field by field.

use super::log::BenchLog;
use super::replay::Rollout;
use crate::error::Error;
use crate::recorder::rrd;
use crate::recorder::rrd::file::RrdFile;
use rerun::TimeColumn;
use rerun::blueprint::components::{PanelState, PlayState};
use rerun::blueprint::{Blueprint, BlueprintActivation, BlueprintPanel, Grid, SelectionPanel, TimePanel, TimeSeriesView, Vertical};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;

/// The timeline: seconds from the log's first row.
pub const TIMELINE: &str = "log_time";

/// The series of one log, each (leaf, the rows' times and values, colour): a measured series only
/// at the rows that have it, none where no row has.
fn series(log: &BenchLog, rollout: &Rollout) -> Vec<(&'static str, Vec<(f64, f64)>, [u8; 3])> {
    const MEASURED: [u8; 3] = [230, 230, 230];
    const SIMULATED: [u8; 3] = [31, 119, 180];
    const GOAL: [u8; 3] = [140, 140, 140];
    let every = |values: &[f64]| log.entries.iter().zip(values).map(|(e, v)| (e.time, *v)).collect::<Vec<_>>();
    let measured = |of: fn(&super::log::Entry) -> Option<f64>| log.entries.iter().filter_map(|e| of(e).map(|v| (e.time, v))).collect::<Vec<_>>();
    let mut out = vec![
        ("position/goal", log.entries.iter().map(|e| (e.time, e.goal)).collect(), GOAL),
        ("position/measured", log.entries.iter().map(|e| (e.time, e.position)).collect(), MEASURED),
        ("position/simulated", every(&rollout.position), SIMULATED),
        ("duty/simulated", every(&rollout.duty), SIMULATED),
        ("supply/model", every(&rollout.supply), SIMULATED),
        ("current/simulated", every(&rollout.current), SIMULATED),
        ("duty/measured", measured(|e| e.duty), MEASURED),
        ("supply/measured", measured(|e| e.volts), MEASURED),
    ];
    out.retain(|(_, rows, _)| !rows.is_empty());
    out
}

/// The `.rrd` of every replayed log.
pub fn write_rrd(path: &Path, runs: &[(&BenchLog, &Rollout)]) -> Result<(), Error> {
    let err = |e: String| Error::output(path, e);
    let file = RrdFile::create(path, true, false).map_err(err)?;
    let rec = rerun::RecordingStreamBuilder::new("armscope-testbench").set_sinks(vec![file.sink()]).map_err(|e| err(e.to_string()))?;
    let mut rows = Vec::new();
    for (log, rollout) in runs {
        let name = crate::runner::file_safe(&log.name());
        for (leaf, rows, colour) in series(log, rollout) {
            let entity = format!("{name}/{leaf}");
            let label = leaf.rsplit('/').next().unwrap_or(leaf);
            rec.log_static(entity.as_str(), &rerun::SeriesLines::new().with_names([label]).with_colors([rerun::Color::from_rgb(colour[0], colour[1], colour[2])])).map_err(|e| err(e.to_string()))?;
            let time = TimeColumn::new_duration_secs(TIMELINE, rows.iter().map(|(t, _)| *t));
            let values: Vec<f64> = rows.iter().map(|(_, v)| *v).collect();
            rrd::send_in_order(&rec, &entity, time, [rrd::scalar_column(&values, 1)]).map_err(|e| err(e.to_string()))?;
        }
        let view = |leaf: &str, title: String| TimeSeriesView::new(title).with_origin(format!("/{name}/{leaf}")).into();
        rows.push(
            Grid::new(vec![
                view("position", format!("{name}: position (rad)")),
                view("duty", format!("{name}: PWM duty")),
                view("supply", format!("{name}: supply (V)")),
                view("current", format!("{name}: current (A)")),
            ])
            .with_grid_columns(4)
            .into(),
        );
    }
    let blueprint = Blueprint::new(Vertical::new(rows))
        .with_time_panel(TimePanel::new().with_timeline(TIMELINE).with_play_state(PlayState::Following).with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed));
    blueprint.send(&rec, BlueprintActivation { make_active: true, make_default: true }).map_err(|e| err(e.to_string()))?;
    rec.flush_blocking().map_err(|e| err(e.to_string()))?;
    drop(rec);
    file.close().map_err(err)
}

/// The JSON schema of a row.
const ROW_SCHEMA: &str = r#"{"type": "object", "properties": {
  "goal_position": {"type": "number"}, "position_measured": {"type": "number"}, "position_sim": {"type": "number"},
  "duty_measured": {"type": "number"}, "duty_sim": {"type": "number"},
  "supply_measured": {"type": "number"}, "supply_model": {"type": "number"},
  "current_sim": {"type": "number"}, "torque_sim": {"type": "number"}, "torque_enable": {"type": "boolean"}}}"#;

/// The `.mcap` of every replayed log: a channel `/testbench/LOG` each, one JSON message a row.
pub fn write_mcap(path: &Path, runs: &[(&BenchLog, &Rollout)]) -> Result<(), Error> {
    let err = |e: String| Error::output(path, e);
    let (file, _replaced) = crate::recorder::shared::output_file::create_replacing(path).map_err(|e| err(e.to_string()))?;
    let mut writer = mcap::WriteOptions::new().compression(None).profile("").create(BufWriter::new(file)).map_err(|e| err(e.to_string()))?;
    let schema = writer.add_schema("armscope.TestbenchRow", "jsonschema", ROW_SCHEMA.as_bytes()).map_err(|e| err(e.to_string()))?;
    for (log, rollout) in runs {
        let name = crate::runner::file_safe(&log.name());
        let metadata = BTreeMap::from([("log".to_string(), log.path.display().to_string()), ("kp".to_string(), log.kp.to_string())]);
        let channel = writer.add_channel(schema, &format!("/testbench/{name}"), "json", &metadata).map_err(|e| err(e.to_string()))?;
        for (row, entry) in log.entries.iter().enumerate() {
            let mut message = serde_json::json!({
                "goal_position": entry.goal,
                "position_measured": entry.position,
                "position_sim": rollout.position[row],
                "duty_sim": rollout.duty[row],
                "supply_model": rollout.supply[row],
                "current_sim": rollout.current[row],
                "torque_sim": rollout.torque[row],
                "torque_enable": entry.enabled,
            });
            if let Some(d) = entry.duty {
                message["duty_measured"] = serde_json::json!(d);
            }
            if let Some(v) = entry.volts {
                message["supply_measured"] = serde_json::json!(v);
            }
            let nanos = (entry.time * 1e9).round() as u64;
            let header = mcap::records::MessageHeader { channel_id: channel, sequence: row as u32, log_time: nanos, publish_time: nanos };
            writer.write_to_known_channel(&header, message.to_string().as_bytes()).map_err(|e| err(e.to_string()))?;
        }
    }
    writer.finish().map_err(|e| err(e.to_string()))?;
    Ok(())
}

/// One CSV per log in `dir`, named after the log's file: `t,goal_position,position_measured,position_sim`.
pub fn write_traces(dir: &Path, runs: &[(&BenchLog, &Rollout)]) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::flag("--trace-dir", format!("{}: {e}", dir.display())))?;
    for (log, rollout) in runs {
        let path = dir.join(format!("{}.csv", log.name()));
        let mut text = String::with_capacity(64 * log.entries.len());
        text += "t,goal_position,position_measured,position_sim\n";
        for (entry, sim) in log.entries.iter().zip(&rollout.position) {
            text += &format!("{},{},{},{}\n", entry.time, entry.goal, entry.position, sim);
        }
        std::fs::write(&path, text).map_err(|e| Error::output(&path, e))?;
    }
    Ok(())
}
