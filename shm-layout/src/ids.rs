//! The ids that name things across the wire: planes within a daemon, bodies within a plane.

/// Identifies a plane within one daemon.
pub type PlaneId = u32;

/// A stable reference to one body: the slot indexes the published array, the generation
/// tells a reused slot from the body that used to live there.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
pub struct Handle {
    /// Index of the body's slot in the published array.
    pub slot: u32,
    /// Generation of the body in that slot.
    pub generation: u32,
}

/// `#slot.generation` (`#3.1`): how messages name an object, with no Rust syntax.
impl core::fmt::Display for Handle {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "#{}.{}", self.slot, self.generation)
    }
}
