//! The versions client and daemon must agree on (checked by the handshake).

/// Bumped whenever a record layout or the command encoding changes. Client and daemon must
/// agree on it; the handshake reports both values when they differ.
pub const LAYOUT_VERSION: u32 = 11;

/// The crate version both sides were built from; also checked by the handshake.
pub const CRATE_VERSION: &str = env!("CARGO_PKG_VERSION");
