//! Recording a plane and replaying the file (docs/recording.md), through real daemons and
//! processes: one test binary whose modules are its subjects.
//!
//! - `replay`: a scenario game recorded on a manual and on a ticking plane and replayed with
//!   every hash equal; `--record DIR`; keyframes and seeks; damaged files; divergences;
//!   Rewind and Restore while recording; refused requests.
//! - `cluster`: a recording of a plane that moves to another daemon.
//! - `kinds`: GUI and DeferGpu planes.
//! - `lua`: `Record = true`, `StartRecording` / `StopRecording`, `physics-lua --replay
//!   [--until]`.

mod cluster;
mod common;
mod kinds;
mod lua;
mod replay;
