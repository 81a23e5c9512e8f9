//! `Dim`: a 2D pixel-space value for GUI primitives and the GUI plane (positions, sizes,
//! velocities in pixels).

use std::fmt;

/// A 2D value: pixel offsets or sizes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dim {
    /// Horizontal component.
    pub x: f64,
    /// Vertical component.
    pub y: f64,
}

impl fmt::Display for Dim {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Dim({}, {})", self.x, self.y)
    }
}

/// A Dim value.
pub fn new_dim(v: [f32; 2]) -> Dim {
    Dim {
        x: v[0] as f64,
        y: v[1] as f64,
    }
}
