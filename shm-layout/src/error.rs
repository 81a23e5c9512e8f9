//! Errors of one command: what kind of failure, which field it concerns (as data), and a
//! message that names the field and the value.

use serde::{Deserialize, Serialize};

/// What kind of failure a command met.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ErrorKind {
    /// A field has a value outside its domain (NaN, negative size, ...).
    InvalidValue,
    /// No plane with that id exists (any more).
    UnknownPlane,
    /// The handle's slot is empty or holds a newer generation.
    StaleHandle,
    /// The request bytes could not be decoded.
    Malformed,
    /// Layout or crate versions of client and daemon differ.
    VersionMismatch,
    /// A command came before `Hello`.
    NotConnected,
    /// The daemon could not do it (resource exhaustion, shared-memory failure, a plane
    /// that failed).
    Internal,
    /// A per-client quota of the daemon would be exceeded; the message names the quota,
    /// its value and the daemon flag that sets it.
    Quota,
    /// The plane belongs to another client, which did not allow this.
    NotOwner,
    /// The plane moved to another daemon of the cluster: the command was not applied;
    /// [`crate::migrate::Moved`] reads where it went.
    Moved,
}

/// The failure of one command. `message` is complete on its own ("Friction must be within
/// [0, 1], got -1"); `field` names the property or argument concerned, when there is one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CommandError {
    /// What kind of failure.
    pub kind: ErrorKind,
    /// The property or argument the error concerns (`"Friction"`, `"Size.Y"`), if any.
    pub field: Option<String>,
    /// A human-readable message naming the field and the value.
    pub message: String,
}

impl CommandError {
    /// An error of `kind` that concerns no particular field.
    pub fn new(kind: ErrorKind, message: impl Into<String>) -> Self {
        CommandError {
            kind,
            field: None,
            message: message.into(),
        }
    }

    /// An invalid value that concerns no single field.
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::new(ErrorKind::InvalidValue, message)
    }

    /// An invalid value of `field`; `message` names the field and the value.
    pub fn invalid_field(field: impl Into<String>, message: impl Into<String>) -> Self {
        CommandError {
            kind: ErrorKind::InvalidValue,
            field: Some(field.into()),
            message: message.into(),
        }
    }

    /// The message without the leading field name, when it starts with it.
    pub fn detail(&self) -> &str {
        match &self.field {
            Some(f) => self
                .message
                .strip_prefix(f.as_str())
                .map_or(self.message.as_str(), str::trim_start),
            None => &self.message,
        }
    }
}

impl core::fmt::Display for CommandError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        // The message is complete on its own; the kind is data (`kind`), not words for people.
        f.write_str(&self.message)
    }
}

impl std::error::Error for CommandError {}
