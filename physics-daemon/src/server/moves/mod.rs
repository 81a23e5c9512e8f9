//! Planes moving between daemons (`plane:MoveTo("DAEMON")`, docs/cluster.md "Migration"):
//! the hook the cluster side fills and the tombstones of planes that left ([`migration`]),
//! and the request loop's side of a move (`relocate`).

pub mod migration;
mod relocate;
