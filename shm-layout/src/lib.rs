//! The wire between the physics daemon and its clients.
//!
//! - [`records`]: `#[repr(C)]` zero-copy records published every tick in shared memory.
//! - [`command`]: the serde command / reply enums carried over request-response.
//! - [`codec`]: framing of those enums into bytes (version header + postcard body).
//! - [`names`]: domain validation and the iceoryx2 service names of one deployment.
//!
//! No simulation code and no I/O live here, so both sides agree on one definition.

pub mod codec;
pub mod command;
pub mod names;
pub mod records;
pub mod validate;

pub use codec::{DecodeError, Frame};
pub use command::*;
pub use records::*;

/// Bumped whenever a record layout or the command encoding changes. Client and daemon must
/// agree on it; the handshake reports both values when they differ.
pub const LAYOUT_VERSION: u32 = 2;

/// The crate version both sides were built from; also checked by the handshake.
pub const CRATE_VERSION: &str = env!("CARGO_PKG_VERSION");
