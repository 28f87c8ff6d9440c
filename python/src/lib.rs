//! `armscope`'s native module (`armscope._armscope`): the library's model and algorithms for Python,
//! NumPy in and out, and the command line. A thin layer: nothing of the physics is written here.

mod model;
mod replay;
mod run;
mod tables;

use pyo3::prelude::*;

pyo3::create_exception!(armscope, ArmscopeError, pyo3::exceptions::PyException, "What armscope refused: its one-line message, as the command line prints it.");

/// An armscope error as the Python exception carrying its one line.
pub(crate) fn error(e: impl std::fmt::Display) -> PyErr {
    ArmscopeError::new_err(e.to_string())
}

/// The `armscope` command with `argv` (its first item the program's name): its exit code.
#[pyfunction]
fn main(argv: Vec<String>) -> i32 {
    armscope::cli::install_interrupt_handler();
    armscope::cli::main_with_args(argv)
}

#[pymodule]
fn _armscope(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("ArmscopeError", m.py().get_type::<ArmscopeError>())?;
    m.add_function(wrap_pyfunction!(main, m)?)?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(replay::replay, m)?)?;
    m.add_function(wrap_pyfunction!(tables::size, m)?)?;
    m.add_function(wrap_pyfunction!(tables::batch, m)?)?;
    m.add_class::<model::Model>()?;
    Ok(())
}
