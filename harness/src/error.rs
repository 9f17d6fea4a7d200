//! What a `morphfx` run ends in when it does not succeed, whichever layer
//! (frame IO, the host, a command) found the fault; its kind is the exit
//! status.

/// Message id the plugin uses for the user's mistakes.
pub const BAD_INPUT_ID: &str = "net.morphfx.BadInput";

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ErrorKind {
    /// Exit status 2: the input is at fault, an output could not be
    /// written, or the run was interrupted (the message says which).
    BadInput,
    /// Exit status 1.
    Failed,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HostError {
    pub kind: ErrorKind,
    pub message: String,
}

impl HostError {
    pub fn bad(m: impl Into<String>) -> Self {
        HostError {
            kind: ErrorKind::BadInput,
            message: m.into(),
        }
    }
    pub fn failed(m: impl Into<String>) -> Self {
        HostError {
            kind: ErrorKind::Failed,
            message: m.into(),
        }
    }
}

impl std::fmt::Display for HostError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}
impl std::error::Error for HostError {}
