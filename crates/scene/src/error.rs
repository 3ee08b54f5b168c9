//! Errors raised while reading a scene and its assets.

use std::path::PathBuf;

/// Everything that can go wrong between a scene file and a renderable [`crate::Scene`].
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A file (scene, mesh or texture) could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file that could not be read.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The scene file is not valid TOML or does not match the format (unknown key, wrong type).
    #[error("{file}:{line}:{column}: {message}")]
    Syntax {
        /// The scene file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What the parser said, naming the key.
        message: String,
    },
    /// A value is well-formed but not allowed (out of range, unknown material, ...).
    #[error("{file}:{line}: {message}")]
    Invalid {
        /// The scene file.
        file: String,
        /// 1-based line of the entity holding the value.
        line: usize,
        /// What is wrong, naming the key and the value.
        message: String,
    },
    /// A line of a text asset (an OBJ file) holds a value pathlight refuses.
    #[error("{}:{line}: {message}", path.display())]
    AssetLine {
        /// The asset file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// What is wrong, with the value.
        message: String,
    },
    /// A referenced asset (mesh or texture) exists but could not be decoded.
    #[error("{path}: {message}")]
    Asset {
        /// The asset file.
        path: PathBuf,
        /// What the decoder said.
        message: String,
    },
}

/// A number outside the range pathlight accepts; the message names the value and the range.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct RangeError(pub String);
