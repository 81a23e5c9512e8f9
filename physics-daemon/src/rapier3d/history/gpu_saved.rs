//! What a snapshot holds of a DeferGpu plane's GPU world.

/// A DeferGpu plane's GPU world as the snapshot holds it: each slot's state and parameters
/// as the shaders hold them (64 bytes each), so a restore on the same adapter continues bit
/// for bit. The GPU path (`crate::gpu::GpuPlane`) fills and reads it; this plane stores it.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub struct GpuSaved {
    /// Each slot's state (64 bytes each).
    pub states: Vec<u8>,
    /// Each slot's parameters (64 bytes each).
    pub params: Vec<u8>,
    /// Whether pairs were found by testing every pair.
    pub brute_force: bool,
    /// The last tick's deepest contact.
    pub max_penetration: f32,
    /// The last tick's touching pairs.
    pub contact_pairs: u32,
}
