use crate::model::ModelError;

/// Everything that can stop armscope, with the exit code it maps to.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A model that cannot be loaded (exit 2).
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A flag or setting with a value that cannot be used (exit 2).
    #[error("{flag}: {message}")]
    Flag { flag: String, message: String },
    /// The simulated state blew up (exit 3).
    #[error("{0}")]
    Diverged(String),
    /// An output file that could not be written (exit 1).
    #[error("{path}: {message}")]
    Output { path: String, message: String },
}

impl Error {
    pub fn flag(flag: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Flag { flag: flag.into(), message: message.into() }
    }

    pub fn output(path: &std::path::Path, err: impl std::fmt::Display) -> Self {
        Error::Output { path: path.display().to_string(), message: err.to_string() }
    }

    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Model(_) | Error::Flag { .. } => 2,
            Error::Diverged(_) => 3,
            Error::Output { .. } => 1,
        }
    }
}
