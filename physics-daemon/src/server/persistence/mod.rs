//! Planes that outlive their owner or their daemon: persistent planes and the state writer
//! ([`persist`]), named planes and their lifecycle in the request loop (`named`), and
//! snapshots in pieces (`transfers`).

mod named;
pub mod persist;
pub(crate) mod transfers;
