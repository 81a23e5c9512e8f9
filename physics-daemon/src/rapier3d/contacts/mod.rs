//! What the plane reads from and adds to rapier's contacts: the contact hook (`hooks`:
//! RestThreshold), the error figures of the tick header (`figures`), contact started /
//! stopped events (`events`) and their manifold points (`points`), the plane's event log
//! (`log`), thin colliders
//! (`thin`), and the exact contacts and casts of boxes of any size (`clipped`) and of
//! capsules (`capsule`). `events.rs` and `points.rs` are the plane's `impl Plane` side; the
//! others know no plane.

pub(super) mod capsule;
pub(super) mod clipped;
mod events;
pub(super) mod figures;
pub(super) mod hooks;
pub(super) mod log;
mod points;
pub(super) mod thin;
