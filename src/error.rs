//! The library's error type: every failure a user can cause ends as one of these, printed as one line.

use std::path::PathBuf;

/// Everything that can stop a lodbench command. The binary prints `error: {self}` and exits non-zero.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("unknown {kind} '{name}'; valid {kind}s: {valid}")]
    UnknownName {
        kind: &'static str,
        name: String,
        valid: String,
    },
    #[error("mesh {path}: {problem}")]
    Mesh { path: String, problem: String },
    #[error("invalid configuration: {0}")]
    Config(String),
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("output folder {}: {problem}", path.display())]
    Output { path: PathBuf, problem: String },
    #[error("{0}")]
    NoAdapter(String),
    #[error("GPU error: {0}")]
    Gpu(String),
    #[error("CSV: {0}")]
    Csv(#[from] csv::Error),
    #[error("JSON: {0}")]
    Json(#[from] serde_json::Error),
    #[error("PNG {}: {problem}", path.display())]
    Image { path: PathBuf, problem: String },
    #[error("results folder {}: {problem}", path.display())]
    Results { path: PathBuf, problem: String },
    #[error("score folder {}: {problem}", path.display())]
    Score { path: PathBuf, problem: String },
    #[error("ColorVideoVDP: {0}")]
    Perceptual(String),
    #[error("calibration {}: {problem}", path.display())]
    Calibration { path: PathBuf, problem: String },
    #[error("interrupted by signal")]
    Interrupted,
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }

    /// A results folder that is not what a command needs (`lodbench perceptual`, `lodbench clips`).
    pub fn results(path: impl Into<PathBuf>, problem: impl Into<String>) -> Self {
        Error::Results {
            path: path.into(),
            problem: problem.into(),
        }
    }

    /// A score folder (`lodbench score`) that breaks the protocol.
    pub fn score(path: impl Into<PathBuf>, problem: impl Into<String>) -> Self {
        Error::Score {
            path: path.into(),
            problem: problem.into(),
        }
    }

    /// An image that cannot be read or written.
    pub fn image(path: impl Into<PathBuf>, problem: impl std::fmt::Display) -> Self {
        Error::Image {
            path: path.into(),
            problem: problem.to_string(),
        }
    }

    pub fn unknown(kind: &'static str, name: &str, valid: &[&str]) -> Self {
        Error::UnknownName {
            kind,
            name: name.to_string(),
            valid: valid.join(", "),
        }
    }
}
