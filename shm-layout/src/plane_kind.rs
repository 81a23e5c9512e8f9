//! The plane kinds: which backend simulates a plane, chosen at creation.

use serde::{Deserialize, Serialize};

/// Which backend simulates a plane. Chosen at creation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum PlaneKind {
    /// A 3D plane simulated by rapier3d on the CPU.
    #[default]
    Rapier3d,
    /// A 2D pixel-space plane for GUI primitives, simulated by rapier2d (`PhysicsService.NewGUI`).
    Gui2d,
}

impl PlaneKind {
    /// The kind in the API's words, for messages: "3D", "GUI".
    pub fn words(self) -> &'static str {
        match self {
            PlaneKind::Rapier3d => "3D",
            PlaneKind::Gui2d => "GUI",
        }
    }
}
