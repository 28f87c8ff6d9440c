//! `armscope.run(**flags)`: `armscope run` in this process — the same flags, parsed by the same
//! command line — with every control step's sample kept as NumPy arrays beside the recordings asked
//! for.

use armscope::recorder::{Recorder, RunInfo};
use armscope::runner::{Outputs, run_experiment};
use armscope::sample::Sample;
use armscope::summary::{RunStatus, Summary};
use clap::Parser;
use armscope::control::law::{LawInput, TorqueLaw};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods};
use numpy::ndarray::Array2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

/// How often Python's main thread looks for Ctrl-C while a run goes on.
const SIGNAL_CHECK: std::time::Duration = std::time::Duration::from_millis(20);

/// `run`'s flags, as the command line parses them.
#[derive(Parser)]
#[command(name = "armscope.run", no_binary_name = true, disable_help_flag = true)]
struct RunCall {
    #[command(flatten)]
    args: armscope::flags::RunArgs,
}

/// Every sample's series, row after row.
#[derive(Default)]
struct Series {
    joints: usize,
    servos: bool,
    t: Vec<f64>,
    q: Vec<f64>,
    q_target: Vec<f64>,
    qd: Vec<f64>,
    qd_target: Vec<f64>,
    tau: Vec<f64>,
    tau_g: Vec<f64>,
    tau_limit: Vec<f64>,
    saturated: Vec<bool>,
    tool_position: Vec<f64>,
    duty: Vec<f64>,
    current: Vec<f64>,
}

/// The recorder that keeps the series (shared with the call that reads them after the run).
struct Keep(Arc<Mutex<Series>>);

impl Recorder for Keep {
    fn start(&mut self, run: &RunInfo) -> Result<(), armscope::Error> {
        let mut s = self.0.lock().expect("one run at a time");
        s.joints = run.experiment.model.dof();
        s.servos = run.experiment.servos.is_some();
        Ok(())
    }

    fn record(&mut self, sample: &Sample) -> Result<(), armscope::Error> {
        let mut s = self.0.lock().expect("one run at a time");
        s.t.push(sample.t);
        s.q.extend_from_slice(sample.q);
        s.q_target.extend_from_slice(sample.cmd);
        s.qd.extend_from_slice(sample.v);
        s.qd_target.extend_from_slice(sample.cmd_dot);
        s.tau.extend_from_slice(sample.u);
        s.tau_g.extend_from_slice(sample.tau_g);
        s.tau_limit.extend_from_slice(sample.torque_limit);
        s.saturated.extend_from_slice(sample.saturated);
        s.tool_position.extend_from_slice(sample.tool_position.as_slice());
        if s.servos {
            s.duty.extend_from_slice(sample.duty);
            s.current.extend_from_slice(sample.current);
        }
        Ok(())
    }

    fn finish(&mut self, _run: &RunInfo, _summary: &Summary) -> Result<(), armscope::Error> {
        Ok(())
    }
}

/// A Python controller as the loop's torque law: `controller(t, q, qd) -> tau` at every control
/// step (NumPy in and out). What it raises is kept for the caller and stops the run.
struct PythonLaw {
    controller: Py<PyAny>,
    joints: usize,
    raised: Arc<Mutex<Option<PyErr>>>,
}

impl PythonLaw {
    fn refuse(&self, t: f64, message: String) -> armscope::Error {
        armscope::Error::flag("controller", format!("at t = {t} s: {message}"))
    }
}

impl TorqueLaw for PythonLaw {
    fn torque(&mut self, input: &LawInput, u: &mut [f64]) -> Result<(), armscope::Error> {
        Python::attach(|py| {
            let q = PyArray1::from_slice(py, input.q);
            let qd = PyArray1::from_slice(py, input.v);
            let result = match self.controller.bind(py).call1((input.t, q, qd)) {
                Ok(r) => r,
                Err(e) => {
                    let message = e.to_string();
                    *self.raised.lock().expect("one run at a time") = Some(e);
                    return Err(self.refuse(input.t, format!("it raised {message}")));
                }
            };
            let tau = match result.cast::<PyArray1<f64>>() {
                Ok(a) => a.clone(),
                Err(_) => {
                    let numpy = py.import("numpy").map_err(|e| self.refuse(input.t, e.to_string()))?;
                    let a = numpy.call_method1("ascontiguousarray", (&result, "float64")).map_err(|_| self.refuse(input.t, format!("it returned {}, not an array of torques", result.get_type().name().map_or("something".into(), |n| n.to_string()))))?;
                    a.cast_into::<PyArray1<f64>>().map_err(|_| self.refuse(input.t, "it returned an array that is not one torque per joint".into()))?
                }
            };
            let read = tau.readonly();
            let values = read.as_slice().map_err(|_| self.refuse(input.t, "it returned a non-contiguous array".into()))?;
            if values.len() != self.joints {
                return Err(self.refuse(input.t, format!("it returned {} torques, the model has {} joints", values.len(), self.joints)));
            }
            if let Some(i) = values.iter().position(|x| !x.is_finite()) {
                return Err(self.refuse(input.t, format!("it returned a torque that is not a finite number for joint {}", i + 1)));
            }
            u.copy_from_slice(values);
            Ok(())
        })
    }
}

/// `armscope run ARGV` with its samples kept (with `controller`, it in place of the PD): a dict of
/// arrays (`t` (N,), per joint (N, nq), the tool's position (N, 3)) and `summary_json`, the text
/// `--summary-json` writes.
#[pyfunction]
#[pyo3(signature = (argv, controller = None))]
pub fn run<'py>(py: Python<'py>, argv: Vec<String>, controller: Option<Py<PyAny>>) -> PyResult<Bound<'py, PyDict>> {
    let call = RunCall::try_parse_from(&argv).map_err(|e| crate::error(format!("run: {}", armscope::cli::parse_error_line(&e))))?;
    let args = call.args;
    let experiment = armscope::experiment::Experiment::prepare(args.config()).map_err(crate::error)?;
    let warnings = py.import("warnings")?;
    for notice in &experiment.model.notices {
        warnings.call_method1("warn", (format!("armscope: {notice}"),))?;
    }
    let scratch = tempfile::tempdir().map_err(crate::error)?;
    let summary_path = scratch.path().join("summary.json");
    let summary_file = summary_path.clone();
    let series = Arc::new(Mutex::new(Series::default()));
    let name = args.name.clone().unwrap_or_else(|| "python".to_string());
    let keep = series.clone();
    let raised = Arc::new(Mutex::new(None));
    let law: Option<Box<dyn TorqueLaw>> = match controller {
        Some(controller) => {
            // an object with reset() starts afresh
            if controller.bind(py).hasattr("reset")? {
                controller.bind(py).call_method0("reset")?;
            }
            Some(Box::new(PythonLaw { controller, joints: experiment.model.dof(), raised: raised.clone() }))
        }
        None => None,
    };
    let make_outputs = move || Outputs {
        name,
        rrd: args.files.rrd.clone(),
        mcap: args.files.mcap.clone(),
        csv: args.csv.clone(),
        trace: args.trace.clone(),
        summary_json: Some(summary_file),
        compress: args.compress,
        mcap_encoding: args.mcap_encoding,
        recorders: vec![Box::new(Keep(keep))],
        law,
        ..Outputs::default()
    };
    // the run on a thread of its own; this one, Python's main, watches for Ctrl-C (Python runs its
    // signal handlers there only): it stops the run, whose recordings then end whole
    let stop = AtomicBool::new(false);
    let mut interrupted: Option<PyErr> = None;
    let result = std::thread::scope(|scope| {
        let (done, finished) = std::sync::mpsc::channel::<()>();
        let finished = Mutex::new(finished);
        let (experiment, stop_flag) = (&experiment, &stop);
        let worker = scope.spawn(move || {
            // the thread keeps one Python thread state for the whole run: a controller attaches at
            // every step, and attaching a thread without one makes and drops it each time (~14 µs)
            let result = Python::attach(|py| py.detach(|| run_experiment(experiment, make_outputs(), Some(stop_flag))));
            let _ = done.send(());
            result
        });
        loop {
            match py.detach(|| finished.lock().map_or(Ok(()), |f| f.recv_timeout(SIGNAL_CHECK))) {
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                    if interrupted.is_none()
                        && let Err(e) = py.check_signals()
                    {
                        interrupted = Some(e);
                        stop.store(true, Ordering::Relaxed);
                    }
                }
                _ => break,
            }
        }
        py.detach(|| worker.join())
    });
    let result = result.map_err(|_| crate::error("the run's thread panicked"))?;
    if let Some(e) = interrupted {
        return Err(e);
    }
    let summary = match result {
        Ok(summary) => summary,
        Err(e) => {
            let error = crate::error(e);
            // the controller's own exception, as the cause
            if let Some(cause) = raised.lock().ok().and_then(|mut r| r.take()) {
                error.set_cause(py, Some(cause));
            }
            return Err(error);
        }
    };
    if let RunStatus::Diverged { message, .. } = &summary.status {
        return Err(crate::error(message));
    }
    let summary_json = std::fs::read_to_string(&summary_path).map_err(crate::error)?;
    let s = std::mem::take(&mut *series.lock().map_err(|_| crate::error("the run's samples were lost"))?);
    let rows = s.t.len();
    let out = PyDict::new(py);
    let table = |v: Vec<f64>, columns: usize| Array2::from_shape_vec((rows, columns), v).map_err(crate::error);
    out.set_item("t", s.t.into_pyarray(py))?;
    for (key, values) in [("q", s.q), ("q_target", s.q_target), ("qd", s.qd), ("qd_target", s.qd_target), ("tau", s.tau), ("tau_g", s.tau_g), ("tau_limit", s.tau_limit)] {
        out.set_item(key, table(values, s.joints)?.into_pyarray(py))?;
    }
    out.set_item("saturated", Array2::from_shape_vec((rows, s.joints), s.saturated).map_err(crate::error)?.into_pyarray(py))?;
    out.set_item("tool_position", table(s.tool_position, 3)?.into_pyarray(py))?;
    if s.servos {
        out.set_item("duty", table(s.duty, s.joints)?.into_pyarray(py))?;
        out.set_item("current", table(s.current, s.joints)?.into_pyarray(py))?;
    }
    out.set_item("summary_json", summary_json)?;
    Ok(out)
}
