//! `armscope.Model`: a URDF's rigid-body model in Pinocchio's shape — built once, read-only — and
//! its algorithms over one state or a whole trajectory at once (an (N, nq) array in, arrays out, the
//! GIL released while they run).

use armscope::dynamics::{self, Data};
use numpy::ndarray::IxDyn;
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use std::sync::Mutex;

/// A robot's rigid-body model, loaded from its URDF (fixed base; the root link welded to the world).
///
/// The algorithms are Pinocchio's, on the URDF's numbers alone (no joint damping, friction or motor:
/// those are the plant's). Each takes one state (arrays of shape (nq,)) or a trajectory of N states
/// ((N, nq) arrays), and returns arrays of the matching shape.
#[pyclass(module = "armscope", frozen)]
pub struct Model {
    model: armscope::model::Model,
    /// The workspace of single-state calls (a trajectory's call makes its own, without the GIL).
    data: Mutex<Data>,
    /// A trajectory's RNEA workspace, made once: each call (each of its tasks, split over the
    /// cores) clones it, sharing the model's numbers in lanes.
    rnea_many: dynamics::RneaManyData,
}

/// A C-contiguous float64 array of `x` (a float64 NumPy array as it is; anything else through
/// numpy.ascontiguousarray).
fn floats<'py>(x: &Bound<'py, PyAny>, name: &str) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(a) = x.cast::<PyArrayDyn<f64>>()
        && a.is_c_contiguous()
    {
        return Ok(a.clone());
    }
    let numpy = x.py().import("numpy")?;
    let bad = || PyTypeError::new_err(format!("{name}: not an array of numbers"));
    let a = numpy.call_method1("ascontiguousarray", (x, "float64")).map_err(|_| bad())?;
    a.cast_into::<PyArrayDyn<f64>>().map_err(|_| bad())
}

/// Whether every value is a finite number: a fold without branches a chunk at a time, which the
/// compiler vectorizes (a trajectory's check is then a small part of its call, not a tenth of it).
fn all_finite(values: &[f64]) -> bool {
    values.chunks(1024).all(|chunk| chunk.iter().fold(true, |finite, v| finite & v.is_finite()))
}

/// The inputs of a call, read in place: `rows` states of `n` values each.
struct States<'py> {
    arrays: Vec<Bound<'py, PyArrayDyn<f64>>>,
    rows: usize,
    /// One state given as a 1-D array (the result drops the leading axis).
    single: bool,
}

/// The most inputs an algorithm takes (q, v, a).
const MOST_INPUTS: usize = 3;
/// Trajectories of at least this many states are split over the cores,
const PARALLEL_FROM: usize = 512;
/// in blocks of this many states (a block's cost, tens of microseconds, far above a task's).
const BLOCK: usize = 128;

impl Model {
    fn dof(&self) -> usize {
        self.model.dof()
    }

    /// The arrays `inputs` (name, value), each (nq,) or (N, nq) alike.
    fn states<'py>(&self, inputs: &[(&str, &Bound<'py, PyAny>)]) -> PyResult<States<'py>> {
        let n = self.dof();
        let mut arrays = Vec::with_capacity(inputs.len());
        for (name, x) in inputs {
            let a = floats(x, name)?;
            let s = a.shape();
            let ok = match s {
                [m] => *m == n,
                [_, m] => *m == n,
                _ => false,
            };
            if !ok {
                return Err(PyValueError::new_err(format!("{name}: shape {s:?}, expected ({n},) or (N, {n}) for this model's {n} coordinates")));
            }
            if let Some(first) = arrays.first()
                && PyUntypedArrayMethods::shape(first) != s
            {
                return Err(PyValueError::new_err(format!("{name}: shape {s:?}, but {} has {:?}", inputs[0].0, PyUntypedArrayMethods::shape(first))));
            }
            // SAFETY: read with the GIL held; the array stays alive in `arrays`
            let values = unsafe { a.as_slice() }.map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
            if !all_finite(values) {
                return Err(PyValueError::new_err(format!("{name}: holds a value that is not a finite number")));
            }
            arrays.push(a);
        }
        let shape = arrays.first().map(|a| a.shape().to_vec()).unwrap_or_default();
        let single = shape.len() == 1;
        Ok(States { arrays, rows: if single { 1 } else { shape[0] }, single })
    }

    /// `each` (the model, its workspace, one state's inputs, where its result goes) over every
    /// state: the result per state has shape `per_state`. A trajectory runs without the GIL, split
    /// over the cores when long.
    fn over<'py>(&self, py: Python<'py>, states: States<'py>, per_state: &[usize], each: impl Fn(&armscope::model::Model, &mut Data, &[&[f64]], &mut [f64]) + Send + Sync) -> PyResult<Bound<'py, PyAny>> {
        let n = self.dof();
        let size: usize = per_state.iter().product::<usize>().max(1);
        if states.single {
            let mut data = self.data.lock().map_err(|_| PyValueError::new_err("the model's workspace was poisoned by a failed call"))?;
            // SAFETY: a new array, written here only; the inputs stay alive (owned here) for the call
            let out = unsafe { PyArrayDyn::<f64>::new(py, IxDyn(per_state), false) };
            let inputs: Vec<&[f64]> = states.arrays.iter().map(|a| unsafe { a.as_slice() }.unwrap_or_default()).collect();
            let written = unsafe { out.as_slice_mut() }.map_err(|e| PyValueError::new_err(e.to_string()))?;
            each(&self.model, &mut data, &inputs, written);
            return Ok(out.into_any());
        }
        self.over_blocks(py, states, per_state, Data::new, |model, data, inputs, out| {
            let mut row: [&[f64]; MOST_INPUTS] = [&[]; MOST_INPUTS];
            for (k, chunk) in out.chunks_mut(size).enumerate() {
                for (slot, x) in row.iter_mut().zip(inputs) {
                    *slot = &x[k * n..(k + 1) * n];
                }
                each(model, data, &row[..inputs.len()], chunk);
            }
        })
    }

    /// `each` (the model, a workspace `init` made, a block of consecutive states' inputs, where
    /// their results go) over every state of a trajectory, a block at a time: the result per state
    /// has shape `per_state`. It runs without the GIL, in blocks of [`BLOCK`] states split over the
    /// cores when long, each core with a workspace of its own.
    fn over_blocks<'py, W>(&self, py: Python<'py>, states: States<'py>, per_state: &[usize], init: impl Fn(&armscope::model::Model) -> W + Send + Sync, each: impl Fn(&armscope::model::Model, &mut W, &[&[f64]], &mut [f64]) + Send + Sync) -> PyResult<Bound<'py, PyAny>> {
        let n = self.dof();
        let size: usize = per_state.iter().product::<usize>().max(1);
        let mut shape = vec![states.rows];
        shape.extend_from_slice(per_state);
        // SAFETY: a new array, written here only
        let out = unsafe { PyArrayDyn::<f64>::new(py, IxDyn(&shape), false) };
        // SAFETY: the inputs and the output stay alive (owned here) for the whole call; a caller
        // changing an input from another thread meanwhile reads what it wrote, as NumPy's own
        // GIL-free functions do
        let inputs: Vec<&[f64]> = states.arrays.iter().map(|a| unsafe { a.as_slice() }.unwrap_or_default()).collect();
        let written = unsafe { out.as_slice_mut() }.map_err(|e| PyValueError::new_err(e.to_string()))?;
        let block_of = |first: usize, rows: usize| -> [&[f64]; MOST_INPUTS] {
            let mut block: [&[f64]; MOST_INPUTS] = [&[]; MOST_INPUTS];
            for (slot, x) in block.iter_mut().zip(&inputs) {
                *slot = &x[first * n..(first + rows) * n];
            }
            block
        };
        let k_inputs = inputs.len();
        let model = &self.model;
        py.detach(|| {
            if states.rows >= PARALLEL_FROM {
                use rayon::prelude::*;
                // a few tasks per core (rayon makes a workspace per task, not per block): enough
                // for a core to take over from one that is slowed, few enough that the workspaces'
                // making (microseconds each) stays out of the time
                let tasks_per_core = 4;
                let blocks_per_task = states.rows.div_ceil(BLOCK).div_ceil(tasks_per_core * rayon::current_num_threads());
                written.par_chunks_mut(size * BLOCK).enumerate().with_min_len(blocks_per_task).for_each_init(|| init(model), |workspace, (b, chunk)| {
                    each(model, workspace, &block_of(b * BLOCK, chunk.len() / size)[..k_inputs], chunk)
                });
            } else {
                each(model, &mut init(model), &block_of(0, states.rows)[..k_inputs], written);
            }
        });
        Ok(out.into_any())
    }

    /// A frame by name or index.
    fn frame(&self, frame: &Bound<'_, PyAny>) -> PyResult<usize> {
        if let Ok(name) = frame.extract::<String>() {
            return self.model.frame_index(&name).ok_or_else(|| {
                let names: Vec<&str> = self.model.frames.iter().map(|f| f.name.as_str()).collect();
                PyValueError::new_err(format!("frame '{name}': no such frame in {} (frames: {})", self.model.source.display(), names.join(", ")))
            });
        }
        let index: usize = frame.extract().map_err(|_| PyTypeError::new_err("frame: a frame's name (str) or index (int)"))?;
        if index >= self.model.frames.len() {
            return Err(PyValueError::new_err(format!("frame {index}: the model has {} frames", self.model.frames.len())));
        }
        Ok(index)
    }
}

#[pymethods]
impl Model {
    /// Load the URDF at `urdf`. What armscope assumes on your behalf (a welded root, a missing mesh)
    /// comes as a Python warning; a URDF it cannot use raises ArmscopeError with its one line.
    #[new]
    fn new(py: Python<'_>, urdf: std::path::PathBuf) -> PyResult<Self> {
        let model = armscope::model::load_urdf(&urdf).map_err(crate::error)?;
        armscope::dynamics::check_solvable(&model).map_err(crate::error)?;
        let warnings = py.import("warnings")?;
        for notice in &model.notices {
            warnings.call_method1("warn", (format!("armscope: {notice}"),))?;
        }
        let data = Mutex::new(Data::new(&model));
        let rnea_many = dynamics::RneaManyData::new(&model);
        Ok(Self { model, data, rnea_many })
    }

    /// The URDF it was loaded from.
    #[getter]
    fn urdf(&self) -> std::path::PathBuf {
        self.model.source.clone()
    }

    /// The number of position coordinates (one per revolute, continuous or prismatic joint).
    #[getter]
    fn nq(&self) -> usize {
        self.dof()
    }

    /// The number of velocity coordinates (= nq: a continuous joint's position is its angle).
    #[getter]
    fn nv(&self) -> usize {
        self.dof()
    }

    /// The joints' names, in coordinate order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.model.joints.iter().map(|j| j.name.clone()).collect()
    }

    /// The frames' names (links and joints), by index.
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        self.model.frames.iter().map(|f| f.name.clone()).collect()
    }

    /// Each coordinate's lower position limit (rad, or m; -inf where none).
    #[getter]
    fn lower_position_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.model.joints.iter().map(|j| j.lower).collect::<Vec<f64>>().into_pyarray(py).into_any()
    }

    /// Each coordinate's upper position limit (rad, or m; inf where none).
    #[getter]
    fn upper_position_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.model.joints.iter().map(|j| j.upper).collect::<Vec<f64>>().into_pyarray(py).into_any()
    }

    /// Each coordinate's effort limit from the URDF (N·m, or N).
    #[getter]
    fn effort_limit<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.model.joints.iter().map(|j| j.effort).collect::<Vec<f64>>().into_pyarray(py).into_any()
    }

    /// Inverse dynamics (RNEA): the joint torques τ = M(q)·a + C(q, v)·v + g(q) that give the
    /// accelerations `a` at positions `q` and velocities `v`.
    fn rnea<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>, v: &Bound<'py, PyAny>, a: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let states = self.states(&[("q", q), ("v", v), ("a", a)])?;
        if states.single {
            return self.over(py, states, &[self.dof()], |model, data, x, out| out.copy_from_slice(dynamics::rnea(model, data, x[0], x[1], x[2])));
        }
        // a trajectory: eight states at a time in SIMD lanes (AVX-512), or four (AVX2)
        self.over_blocks(py, states, &[self.dof()], |_| self.rnea_many.clone(), |model, data, x, out| dynamics::rnea_many(model, data, x[0], x[1], x[2], out))
    }

    /// Forward dynamics (ABA): the accelerations the torques `tau` give at positions `q` and
    /// velocities `v`.
    fn aba<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>, v: &Bound<'py, PyAny>, tau: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let states = self.states(&[("q", q), ("v", v), ("tau", tau)])?;
        self.over(py, states, &[self.dof()], |model, data, x, out| out.copy_from_slice(dynamics::aba(model, data, x[0], x[1], x[2])))
    }

    /// The joint-space mass matrix M(q) (CRBA), symmetric, (nq, nq).
    fn mass_matrix<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let states = self.states(&[("q", q)])?;
        let n = self.dof();
        self.over(py, states, &[n, n], move |model, data, x, out| {
            let m = dynamics::crba(model, data, x[0]);
            for i in 0..n {
                for j in 0..n {
                    out[i * n + j] = m[(i, j)];
                }
            }
        })
    }

    /// The generalized gravity g(q): the torques gravity asks of the joints at rest — the torque
    /// that holds the arm still is +g(q) (Pinocchio's computeGeneralizedGravity, rnea(q, 0, 0)).
    fn gravity_torque<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let states = self.states(&[("q", q)])?;
        // armscope's τ_g is the force gravity applies (Drake's sign); Pinocchio's g is what holds it
        self.over(py, states, &[self.dof()], |model, data, x, out| {
            for (o, g) in out.iter_mut().zip(dynamics::gravity_forces(model, data, x[0])) {
                *o = -g;
            }
        })
    }

    /// The pose of `frame` (its name or index) in the world at positions `q`: a 4×4 homogeneous
    /// transform (rotation, then translation in m), Pinocchio's oMf.
    fn frame_pose<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>, frame: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let f = self.frame(frame)?;
        let states = self.states(&[("q", q)])?;
        self.over(py, states, &[4, 4], move |model, data, x, out| {
            dynamics::forward_kinematics(model, data, x[0]);
            let pose = dynamics::frame_pose(model, data, f);
            out.fill(0.0);
            for i in 0..3 {
                for j in 0..3 {
                    out[i * 4 + j] = pose.rotation[(i, j)];
                }
                out[i * 4 + 3] = pose.translation[i];
            }
            out[15] = 1.0;
        })
    }

    /// The Jacobian of `frame` (its name or index) at positions `q`, 6 × nq, in Pinocchio's
    /// LOCAL_WORLD_ALIGNED convention: rows 0–2 the velocity of the frame's origin, rows 3–5 its
    /// angular velocity, both in world axes.
    fn jacobian<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>, frame: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let f = self.frame(frame)?;
        let states = self.states(&[("q", q)])?;
        let n = self.dof();
        self.over(py, states, &[6, n], move |model, data, x, out| {
            dynamics::forward_kinematics(model, data, x[0]);
            let mut j = nalgebra::DMatrix::zeros(6, n);
            dynamics::frame_jacobian(model, data, f, &mut j);
            // armscope's rows are angular then linear; Pinocchio's linear then angular
            for c in 0..n {
                for r in 0..3 {
                    out[r * n + c] = j[(r + 3, c)];
                    out[(r + 3) * n + c] = j[(r, c)];
                }
            }
        })
    }

    fn __repr__(&self) -> String {
        format!("armscope.Model('{}': {} joints, {} frames)", self.model.source.display(), self.dof(), self.model.frames.len())
    }
}
