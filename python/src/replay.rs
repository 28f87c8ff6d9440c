//! `armscope.replay(source, urdf=…)`: `armscope replay` in this process — a recorded motion (a
//! LeRobot dataset, a ROS 2 bag, a CSV) read as the command reads it — each episode's smoothed
//! motion, the torque it needed, what the joints had, and the verdicts, as NumPy arrays.

use armscope::motion::{BodyUnits, Mapped, Reading, open_mapped};
use armscope::replay::{ReplayOptions, Replayer};
use clap::ValueEnum;
use numpy::IntoPyArray;
use numpy::ndarray::Array2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Per coordinate, per sample → (samples, coordinates).
fn table(per_joint: &[Vec<f64>]) -> Array2<f64> {
    let rows = per_joint.first().map_or(0, Vec::len);
    Array2::from_shape_fn((rows, per_joint.len()), |(k, j)| per_joint[j][k])
}

/// Every episode of `source` (or `episodes`) replayed on `urdf`: a list of dicts, one an episode.
#[pyfunction]
#[pyo3(signature = (source, urdf, motors = None, payload = 0.0, tool = None, episodes = None, feature = "observation.state".to_string(), joint_map = None, units = None, calibration = None))]
#[allow(clippy::too_many_arguments)]
pub fn replay<'py>(
    py: Python<'py>,
    source: PathBuf,
    urdf: PathBuf,
    motors: Option<PathBuf>,
    payload: f64,
    tool: Option<String>,
    episodes: Option<Vec<i64>>,
    feature: String,
    joint_map: Option<PathBuf>,
    units: Option<String>,
    calibration: Option<PathBuf>,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let units = match units.as_deref() {
        Some(u) => Some(BodyUnits::from_str(u, true).map_err(|_| crate::error(format!("units: '{u}' is not degrees or range")))?),
        None => None,
    };
    let model = armscope::model::load_urdf(&urdf).map_err(crate::error)?;
    let warnings = py.import("warnings")?;
    let reading = Reading { units, calibration: calibration.as_deref() };
    let opened = match open_mapped(&source, None, episodes.as_deref(), &feature, joint_map.as_deref(), reading, &model).map_err(crate::error)? {
        Mapped::Ready(r) => r,
        Mapped::NeedsMap { .. } => return Err(crate::error(format!("joint_map: needed: armscope knows no map from {}'s columns to {}'s joints (`armscope replay` prints a template)", source.display(), urdf.display()))),
    };
    for notice in model.notices.iter().chain(&opened.notices) {
        warnings.call_method1("warn", (format!("armscope: {notice}"),))?;
    }
    let replayer = Replayer::new(model, &ReplayOptions { payload, tool, motors }, opened.map).map_err(crate::error)?;
    let mut out = Vec::with_capacity(opened.episodes.len());
    let mut past = Vec::with_capacity(opened.episodes.len());
    for &index in &opened.episodes {
        let replayed = py.detach(|| -> Result<_, armscope::Error> {
            let episode = opened.source.read(index, &feature)?;
            Ok((episode.notices.clone(), replayer.replay(&episode)?))
        });
        let (notices, replayed) = replayed.map_err(crate::error)?;
        for notice in notices.iter().chain(&replayed.motion.notices) {
            warnings.call_method1("warn", (format!("armscope: {notice}"),))?;
        }
        let m = &replayed.motion;
        past.push(m.past_limits.clone());
        let d = PyDict::new(py);
        d.set_item("episode", index)?;
        d.set_item("t", m.time.clone().into_pyarray(py))?;
        d.set_item("q", table(&m.q).into_pyarray(py))?;
        d.set_item("qd", table(&m.qd).into_pyarray(py))?;
        d.set_item("qdd", table(&m.qdd).into_pyarray(py))?;
        d.set_item("tau", table(&m.needed).into_pyarray(py))?;
        d.set_item("available", table(&replayed.available).into_pyarray(py))?;
        d.set_item("verdicts_json", serde_json::to_string(&replayed.verdicts).map_err(crate::error)?)?;
        out.push(d);
    }
    if let Some(notice) = armscope::replay::past_limits::notice(&replayer.model, past.iter().map(Vec::as_slice)) {
        warnings.call_method1("warn", (format!("armscope: {notice}"),))?;
    }
    Ok(out)
}
