//! Recording a plane ([`PlaneOp::Record`](crate::PlaneOp::Record)): the plane writes its
//! start state, every batch of ops applied to it, each tick's state hash and a keyframe
//! every so many ticks to a file ([`crate::recording`]) that replays it bit for bit.

use serde::{Deserialize, Serialize};

/// Starts or stops the plane's recording. Owner only.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum RecordOp {
    /// Starts recording into a new file at `path` on the daemon's machine (refused when the
    /// file exists or the plane records already). An empty path: the daemon names a file in
    /// its `--record` folder, or in `physics-recordings` under the system's temporary folder.
    /// Replies [`crate::Reply::Recording`] (the path, nothing recorded yet).
    Start {
        /// The file to create (absolute; clients resolve relative paths before sending).
        path: String,
    },
    /// Stops recording: the file is closed (an end entry written) before the reply, which is
    /// [`crate::Reply::Recording`] with what was written, or [`crate::Reply::Done`] when the
    /// plane was not recording.
    Stop,
}

/// What a recording holds, as [`crate::Reply::Recording`] reports it.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct RecordingInfo {
    /// The file.
    pub path: String,
    /// Ticks recorded.
    pub ticks: u64,
    /// Bytes written (all of them once stopped).
    pub bytes: u64,
}
