//! The one error type of the crate.
//!
//! Every fault a user can provoke — a bad mesh file, a corrupt or truncated stream, a mesh a codec
//! cannot take, a count past a limit — becomes one of these variants; nothing panics on input.
//! Binaries print it on one line, prefixed with the file it concerns (docs/CONTRACT.md §7).

use std::fmt;

/// Everything that can go wrong while reading meshes or streams.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A stream whose bytes contradict its own syntax.
    #[error("malformed stream: {what} (level {level}, byte {byte})")]
    Malformed {
        /// Level being decoded when the fault was found (0 = header).
        level: usize,
        /// Byte offset from the start of the stream.
        byte: usize,
        /// What was wrong.
        what: String,
    },
    /// The input ends before something that must be there (a stream header, a PLY payload).
    #[error("truncated: {0}")]
    Truncated(String),
    /// Valid input that this codec or reader cannot handle, with the reason.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// A count beyond what this crate accepts or the input can justify.
    #[error("limit exceeded: {0}")]
    Limit(String),
    /// A mesh file that cannot be parsed, or a mesh that breaks a rule (NaN, index out of range…).
    #[error("{0}")]
    InvalidMesh(MeshFault),
    /// Operating-system I/O failure.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

/// Where in a mesh file a fault sits, and what it is.
#[derive(Debug)]
pub struct MeshFault {
    /// 1-based line of a text file, if known.
    pub line: Option<usize>,
    /// Description of the fault.
    pub what: String,
}

impl fmt::Display for MeshFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "line {line}: {}", self.what),
            None => write!(f, "{}", self.what),
        }
    }
}

impl Error {
    /// A mesh fault with no line number.
    pub fn mesh(what: impl Into<String>) -> Self {
        Error::InvalidMesh(MeshFault {
            line: None,
            what: what.into(),
        })
    }

    /// A mesh fault at a 1-based line of a text file.
    pub fn mesh_at(line: usize, what: impl Into<String>) -> Self {
        Error::InvalidMesh(MeshFault {
            line: Some(line),
            what: what.into(),
        })
    }

    /// A stream fault at a byte offset.
    pub fn malformed(level: usize, byte: usize, what: impl Into<String>) -> Self {
        Error::Malformed {
            level,
            byte,
            what: what.into(),
        }
    }

    /// The same error, its text prefixed with `what` it concerns ("mesh 2 primitive 0: …"),
    /// its kind kept.
    pub fn context(self, what: &str) -> Self {
        match self {
            Error::Malformed {
                level,
                byte,
                what: w,
            } => Error::Malformed {
                level,
                byte,
                what: format!("{what}: {w}"),
            },
            Error::Truncated(w) => Error::Truncated(format!("{what}: {w}")),
            Error::Unsupported(w) => Error::Unsupported(format!("{what}: {w}")),
            Error::Limit(w) => Error::Limit(format!("{what}: {w}")),
            Error::InvalidMesh(f) => Error::InvalidMesh(MeshFault {
                line: f.line,
                what: format!("{what}: {}", f.what),
            }),
            Error::Io(e) => Error::Io(std::io::Error::new(e.kind(), format!("{what}: {e}"))),
        }
    }
}

/// Result with the crate's error.
pub type Result<T, E = Error> = std::result::Result<T, E>;
