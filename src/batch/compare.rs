//! The comparison recording: several runs in one `.rrd`, each under its own entity prefix, with a
//! blueprint that overlays them per joint (tracking error, torque). A batch hands each run's series
//! to it as the run ends ([`SeriesRecorder`], kept in memory while the run goes on); `armscope
//! compare A.mcap B.mcap …` and the merge of shards read them back from the runs' `.mcap` files.

use crate::error::Error;
use crate::recorder::rrd::file::RrdFile;
use crate::recorder::{ControllerTelemetry, Recorder, RunInfo, TOPIC_CONTROLLER, TOPIC_JOINT_STATES, rrd};
use crate::sample::Sample;
use crate::summary::Summary;
use foxglove::messages::JointStates;
use prost::Message as _;
use rerun::blueprint::components::{PanelState, PlayState};
use rerun::blueprint::{Blueprint, BlueprintActivation, BlueprintPanel, Grid, SelectionPanel, TimePanel, TimeSeriesView, Vertical};
use rerun::{RecordingStream, TimeColumn};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

#[derive(Clone, Debug)]
pub struct ComparedRun {
    /// The run's entity prefix and legend name.
    pub label: String,
    pub mcap: PathBuf,
}

/// Per-step series of one run: the coordinates' names, and per coordinate its tracking error,
/// torque and angle at every control step.
#[derive(Debug, Default, PartialEq)]
pub struct RunSeries {
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
                let t = match message.channel.message_encoding.as_str() {
                    "protobuf" => ControllerTelemetry::decode(&message.data[..]).map_err(|e| fail(e.to_string()))?,
                    "cdr" => crate::recorder::decode_controller_telemetry(&message.data).map_err(|e| fail(format!("{TOPIC_CONTROLLER}: {e}")))?,
                    other => return Err(fail(format!("{TOPIC_CONTROLLER} is {other}-encoded: recorded by an older armscope, record it again"))),
                };
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
                let (names, positions): (Vec<String>, Vec<f64>) = if message.channel.message_encoding == "cdr" {
                    use crate::ros2::Message as _;
                    let js = crate::ros2::messages::JointState::decode(&message.data).map_err(|e| fail(format!("{TOPIC_JOINT_STATES}: {e}")))?;
                    (js.name, js.position)
                } else {
                    let js = JointStates::decode(&message.data[..]).map_err(|e| fail(e.to_string()))?;
                    js.joints.iter().map(|j| (j.name.clone(), j.position.unwrap_or(f64::NAN))).unzip()
                };
                if series.joints.is_empty() {
                    series.angle = vec![Vec::new(); names.len()];
                    series.joints = names;
                }
                for (j, position) in positions.iter().enumerate().take(series.angle.len()) {
                    series.angle[j].push(*position);
                }
            }
            _ => {}
        }
    }
    if series.time.is_empty() || series.joints.is_empty() {
        return Err(fail("no /controller or /joint_states messages: not an armscope recording".into()));
    }
    // /joint_states also carries the mimic joints, after the coordinates; only coordinates are compared
    series.joints.truncate(series.error.len());
    series.angle.truncate(series.error.len());
    Ok(series)
}

/// Every step's series, kept while the run goes on and handed to the batch when it ends (the same
/// values the `.mcap`'s `/controller` and `/joint_states` carry, without encoding and decoding them).
pub struct SeriesRecorder {
    series: RunSeries,
    finished: Arc<Mutex<Option<RunSeries>>>,
}

impl SeriesRecorder {
    /// The recorder and where its series will be when the run has finished.
    pub fn new() -> (Self, Arc<Mutex<Option<RunSeries>>>) {
        let finished = Arc::new(Mutex::new(None));
        (Self { series: RunSeries::default(), finished: finished.clone() }, finished)
    }
}

impl Recorder for SeriesRecorder {
    fn start(&mut self, run: &RunInfo) -> Result<(), Error> {
        let model = &run.experiment.model;
        let n = model.dof();
        let steps = run.experiment.steps + 1;
        self.series = RunSeries {
            joints: model.joints.iter().map(|j| j.name.clone()).collect(),
            time: Vec::with_capacity(steps),
            angle: vec![Vec::with_capacity(steps); n],
            error: vec![Vec::with_capacity(steps); n],
            torque: vec![Vec::with_capacity(steps); n],
        };
        Ok(())
    }

    fn record(&mut self, s: &Sample) -> Result<(), Error> {
        let series = &mut self.series;
        series.time.push(s.t);
        for j in 0..s.q.len() {
            series.angle[j].push(s.q[j]);
            series.error[j].push(s.tracking_error(j));
            series.torque[j].push(s.u[j]);
        }
        Ok(())
    }

    fn finish(&mut self, _: &RunInfo, _: &Summary) -> Result<(), Error> {
        *self.finished.lock().unwrap_or_else(|e| e.into_inner()) = Some(std::mem::take(&mut self.series));
        Ok(())
    }
}

/// The comparison `.rrd`, open while runs are added to it (from any thread: Rerun's stream encodes
/// and writes on threads of its own).
pub struct Comparison {
    rec: RecordingStream,
    file: RrdFile,
    out: PathBuf,
    /// The joints of the first run (by place) added so far: the blueprint's views.
    joints: Mutex<Option<(usize, Vec<String>)>>,
}

impl Comparison {
    /// Written as the runs' own `.rrd` files are (Rerun's encoder without LZ4, see `RrdFile`).
    pub fn create(out: &Path, name: &str) -> Result<Self, Error> {
        let file = RrdFile::create(out, true, false).map_err(|e| Error::output(out, e))?;
        let rec = rerun::RecordingStreamBuilder::new("armscope-compare").recording_name(name).set_sinks(vec![file.sink()]).map_err(|e| Error::output(out, e))?;
        Ok(Self { rec, file, out: out.to_path_buf(), joints: Mutex::new(None) })
    }

    /// One run's series under `label/joints/JOINT/{error,torque,angle}`, drawn in the colour of
    /// its place `index` among the compared runs.
    pub fn add(&self, label: &str, index: usize, s: &RunSeries) -> Result<(), Error> {
        let out = &self.out;
        let e = |err: rerun::RecordingStreamError| Error::output(out, err);
        let label = crate::runner::file_safe(label);
        let color = rrd::joint_color(index);
        {
            let mut first = self.joints.lock().unwrap_or_else(|e| e.into_inner());
            if first.as_ref().is_none_or(|(place, _)| index < *place) {
                *first = Some((index, s.joints.clone()));
            }
        }
        for (j, joint) in s.joints.iter().enumerate().take(s.error.len()) {
            for (leaf, values) in [("error", &s.error[j]), ("torque", &s.torque[j]), ("angle", &s.angle[j])] {
                let path = format!("{label}/joints/{joint}/{leaf}");
                self.rec.log_static(path.as_str(), &rerun::SeriesLines::new().with_names([label.clone()]).with_colors([color])).map_err(e)?;
                let n = values.len().min(s.time.len());
                // rows already in time order: sent as they are (see `rrd::send_in_order`)
                let time = TimeColumn::new_duration_secs(rrd::TIMELINE, s.time[..n].iter().copied());
                rrd::send_in_order(&self.rec, &path, time, [rrd::scalar_column(&values[..n], 1)]).map_err(|x| Error::output(out, x))?;
            }
        }
        Ok(())
    }

    /// The blueprint (one view per joint of the first run, overlaying the runs `labels`, in that
    /// order), and the file flushed whole.
    pub fn finish(self, labels: &[String]) -> Result<(), Error> {
        let out = &self.out;
        let joints = self.joints.lock().unwrap_or_else(|e| e.into_inner()).take().map(|(_, joints)| joints).unwrap_or_default();
        let labels: Vec<String> = labels.iter().map(|l| crate::runner::file_safe(l)).collect();
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
        blueprint.send(&self.rec, BlueprintActivation { make_active: true, make_default: true }).map_err(|x| Error::output(out, x))?;
        self.rec.flush_blocking().map_err(|x| Error::output(out, x))?;
        drop(self.rec);
        self.file.close().map_err(|e| Error::output(out, e))
    }
}

/// The comparison of finished runs, read back from their `.mcap` files.
pub fn build_comparison(runs: &[ComparedRun], out: &Path, name: &str) -> Result<(), Error> {
    let all: Vec<RunSeries> = runs.iter().map(read_run).collect::<Result<_, _>>()?;
    let comparison = Comparison::create(out, name)?;
    for (index, (run, series)) in runs.iter().zip(&all).enumerate() {
        comparison.add(&run.label, index, series)?;
    }
    let labels: Vec<String> = runs.iter().map(|r| r.label.clone()).collect();
    comparison.finish(&labels)
}
