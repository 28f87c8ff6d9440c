//! The comparison recording: several runs in one `.rrd`, each under its own entity prefix, with a
//! blueprint that overlays them per joint (tracking error, torque). Built from the runs' `.mcap`
//! files, so it works for any set of finished runs (`armscope compare A.mcap B.mcap …`).

use crate::error::Error;
use crate::recorder::{ControllerTelemetry, TOPIC_CONTROLLER, TOPIC_JOINT_STATES, rrd};
use foxglove::messages::JointStates;
use prost::Message as _;
use rerun::blueprint::components::{PanelState, PlayState};
use rerun::blueprint::{Blueprint, BlueprintActivation, BlueprintPanel, Grid, SelectionPanel, TimePanel, TimeSeriesView, Vertical};
use rerun::TimeColumn;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug)]
pub struct ComparedRun {
    /// The run's entity prefix and legend name.
    pub label: String,
    pub mcap: PathBuf,
}

/// Per-step series of one run, read back from its MCAP.
struct RunSeries {
    joints: Vec<String>,
    time: Vec<f64>,
    angle: Vec<Vec<f64>>,
    error: Vec<Vec<f64>>,
    torque: Vec<Vec<f64>>,
}

fn read_run(run: &ComparedRun) -> Result<RunSeries, Error> {
    let fail = |m: String| Error::flag("compare", format!("{}: {m}", run.mcap.display()));
    let bytes = std::fs::read(&run.mcap).map_err(|e| fail(e.to_string()))?;
    let mut series = RunSeries { joints: Vec::new(), time: Vec::new(), angle: Vec::new(), error: Vec::new(), torque: Vec::new() };
    let stream = mcap::MessageStream::new(&bytes).map_err(|e| fail(e.to_string()))?;
    for message in stream {
        let message = message.map_err(|e| fail(e.to_string()))?;
        match message.channel.topic.as_str() {
            TOPIC_CONTROLLER => {
                if message.channel.message_encoding != "protobuf" {
                    return Err(fail(format!("{TOPIC_CONTROLLER} is {}-encoded: recorded by an older armscope, record it again", message.channel.message_encoding)));
                }
                let t = ControllerTelemetry::decode(&message.data[..]).map_err(|e| fail(e.to_string()))?;
                if series.error.is_empty() {
                    series.error = vec![Vec::new(); t.error.len()];
                    series.torque = vec![Vec::new(); t.torque.len()];
                }
                series.time.push(t.time);
                for j in 0..t.error.len().min(series.error.len()) {
                    series.error[j].push(t.error[j]);
                    series.torque[j].push(t.torque[j]);
                }
            }
            TOPIC_JOINT_STATES => {
                let js = JointStates::decode(&message.data[..]).map_err(|e| fail(e.to_string()))?;
                if series.joints.is_empty() {
                    series.joints = js.joints.iter().map(|j| j.name.clone()).collect();
                    series.angle = vec![Vec::new(); js.joints.len()];
                }
                for (j, state) in js.joints.iter().enumerate().take(series.angle.len()) {
                    series.angle[j].push(state.position.unwrap_or(f64::NAN));
                }
            }
            _ => {}
        }
    }
    if series.time.is_empty() || series.joints.is_empty() {
        return Err(fail("no /controller or /joint_states messages: not an armscope recording".into()));
    }
    Ok(series)
}

pub fn build_comparison(runs: &[ComparedRun], out: &Path, name: &str) -> Result<(), Error> {
    let all: Vec<(String, RunSeries)> = runs.iter().map(|r| read_run(r).map(|s| (crate::runner::file_safe(&r.label), s))).collect::<Result<_, _>>()?;
    let joints = all[0].1.joints.clone();
    let rec = rerun::RecordingStreamBuilder::new("armscope-compare").recording_name(name).save(out).map_err(|e| Error::output(out, e))?;
    let e = |err: rerun::RecordingStreamError| Error::output(out, err);
    for (i, (label, s)) in all.iter().enumerate() {
        let color = rrd::joint_color(i);
        for (j, joint) in joints.iter().enumerate().take(s.error.len()) {
            for (leaf, values) in [("error", &s.error[j]), ("torque", &s.torque[j]), ("angle", &s.angle[j])] {
                let path = format!("{label}/joints/{joint}/{leaf}");
                rec.log_static(path.as_str(), &rerun::SeriesLines::new().with_names([label.clone()]).with_colors([color])).map_err(e)?;
                let n = values.len().min(s.time.len());
                let columns = rerun::Scalars::new(values[..n].iter().copied()).columns_of_unit_batches().map_err(|x| Error::output(out, x))?;
                rec.send_columns(path.as_str(), [TimeColumn::new_duration_secs(rrd::TIMELINE, s.time[..n].iter().copied())], columns).map_err(e)?;
            }
        }
    }
    let labels: Vec<&String> = all.iter().map(|(l, _)| l).collect();
    let views = |leaf: &'static str, title: &'static str| {
        joints
            .iter()
            .map(|j| {
                TimeSeriesView::new(format!("{j} {title}"))
                    .with_contents(labels.iter().map(|l| format!("/{l}/joints/{j}/{leaf}")).collect::<Vec<_>>())
                    .into()
            })
            .collect::<Vec<_>>()
    };
    let columns = joints.len().div_ceil(2).clamp(1, 4) as u32;
    let blueprint = Blueprint::new(Vertical::new([
        Grid::new(views("error", "tracking error (rad)")).with_grid_columns(columns).with_name("tracking error").into(),
        Grid::new(views("torque", "torque (N·m)")).with_grid_columns(columns).with_name("torque").into(),
    ]))
    .with_time_panel(TimePanel::new().with_timeline(rrd::TIMELINE).with_play_state(PlayState::Following).with_state(PanelState::Collapsed))
    .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
    .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed));
    blueprint.send(&rec, BlueprintActivation { make_active: true, make_default: true }).map_err(|x| Error::output(out, x))?;
    rec.flush_blocking().map_err(|x| Error::output(out, x))?;
    Ok(())
}
