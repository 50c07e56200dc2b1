//! Error types of trum-core. Every message names where the problem is (file, line, key
//! or column) and why, so the CLI and Python can show it unchanged.
use std::fmt;

/// A problem with a motor definition or another parameter set.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamError {
    /// Where the parameters came from (file name, `preset 'trum60a'`, `dict`, ...).
    pub source_name: String,
    /// 1-based line in the source text, when known.
    pub line: Option<usize>,
    /// Dotted key path (`stator.modal_mass_kg`), empty when the problem is not one key.
    pub key: String,
    /// Why the value was rejected.
    pub reason: String,
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.source_name)?;
        if let Some(l) = self.line {
            write!(f, ": line {l}")?;
        }
        if !self.key.is_empty() {
            write!(f, ", key '{}'", self.key)?;
        }
        write!(f, ": {}", self.reason)
    }
}

impl std::error::Error for ParamError {}

/// Errors of trum-core.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrumError {
    /// A parameter (motor file, preset override, effect, operating point) is invalid.
    #[error("{0}")]
    Param(#[from] ParamError),
    /// An operating point or sweep argument is invalid.
    #[error("{0}")]
    Input(String),
}

impl TrumError {
    /// An input error with a message.
    pub fn input(msg: impl Into<String>) -> Self {
        TrumError::Input(msg.into())
    }
}
