//! One error type for the core: every error says what is wrong and where.

use thiserror::Error;

/// The core's result: [`enum@Error`] unless said otherwise.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// What went wrong, with where (scene errors name the place).
#[derive(Debug, Error, Clone, PartialEq)]
pub enum Error {
    /// A scene (file or string) breaks the format's rules. `at` names the place:
    /// `features[2] "nose"`, `keyframes[1] (frame 1024)`, `field.b`, ...
    #[error("scene: {at}: {message}")]
    Scene {
        /// Where: `features[2] "nose"`, `field.b`, ...
        at: String,
        /// What is wrong there.
        message: String,
    },
    /// Input that is well formed but cannot be used (sizes, empty feature sets).
    #[error("{0}")]
    Invalid(String),
    /// Something this build does not do (yet).
    #[error("not supported: {0}")]
    Unsupported(String),
    /// Stopped on request (a host's cancel, Ctrl-C) before the end.
    #[error("cancelled")]
    Cancelled,
}

impl Error {
    /// A scene error at `at` (a path such as `features[2] "nose"`).
    pub fn scene(at: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Scene {
            at: at.into(),
            message: message.into(),
        }
    }
}
