//! The answers the server gives on its own: a plane that is not there, a daemon failure met
//! by a command, and the text of a caught panic.

use shm_layout::{CommandError, ErrorKind, PlaneId};

use crate::DaemonError;

/// The error for a plane that is not (or no longer) there.
pub(crate) fn unknown_plane(id: PlaneId) -> CommandError {
    CommandError::new(
        ErrorKind::UnknownPlane,
        format!("plane {id} does not exist"),
    )
}

/// A daemon failure as the error of the command that met it.
pub(crate) fn internal(e: DaemonError) -> CommandError {
    CommandError::new(ErrorKind::Internal, e.to_string())
}

/// The text of a caught panic.
pub(crate) fn panic_message(panic: &(dyn std::any::Any + Send)) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".to_string())
}
