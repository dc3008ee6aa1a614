//! The crate's error type.

use anim_core::mesh::ValidationReport;
use std::path::PathBuf;

/// Everything that can go wrong reading or writing a file.
///
/// Reader errors name the file, the line (1-based) and the cause; mesh validation failures name
/// the offending elements by index.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IoError {
    /// The operating system refused a read or write.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A malformed input file.
    #[error("{file}:{line}: {cause}")]
    Parse {
        /// The file name as given to the reader.
        file: String,
        /// 1-based line number (one past the last line for an unexpected end of file).
        line: usize,
        /// What is wrong.
        cause: String,
    },
    /// A mesh that parsed but failed validation (out-of-range indices, degenerate or inverted
    /// elements, non-finite coordinates).
    #[error("{file}: invalid mesh: {report}")]
    InvalidMesh {
        /// The file name as given to the reader.
        file: String,
        /// Every problem found, by element or vertex index (boxed: it keeps the error small).
        report: Box<ValidationReport>,
    },
    /// Data handed to a writer that cannot be written as asked (mismatched lengths, an index past
    /// the last point, a cell kind the format cannot hold).
    #[error("{what}: {cause}")]
    InvalidData {
        /// The file or object being written.
        what: String,
        /// What is wrong.
        cause: String,
    },
    /// A checkpoint file that cannot be resumed from: not a checkpoint, another version,
    /// truncated, corrupted, or a payload that does not parse.
    #[error("{}: {problem}", path.display())]
    Checkpoint {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: crate::checkpoint::CheckpointProblem,
    },
    /// An encoder (PNG, GIF, CSV, JSON) failed.
    #[error("{}: {cause}", path.display())]
    Encode {
        /// The file being written.
        path: PathBuf,
        /// The encoder's message.
        cause: String,
    },
}

impl IoError {
    /// An [`IoError::Io`] for `path`.
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        IoError::Io { path: path.into(), source }
    }

    /// An [`IoError::InvalidData`].
    pub(crate) fn data(what: impl std::fmt::Display, cause: impl Into<String>) -> Self {
        IoError::InvalidData { what: what.to_string(), cause: cause.into() }
    }

    /// An [`IoError::Encode`].
    pub(crate) fn encode(path: impl Into<PathBuf>, cause: impl std::fmt::Display) -> Self {
        IoError::Encode { path: path.into(), cause: cause.to_string() }
    }
}
