//! The solver knobs a case runs at ([`Setting`]) and the ranges they are drawn from
//! ([`SettingRanges`]).

use crate::rng::Span;

/// The solver knobs a case runs at (every case carries its own).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Setting {
    /// Ticks per simulated second (the plane is stepped by hand at `1 / tick_rate`).
    pub tick_rate: f32,
    pub iterations: u32,
    /// HitBoxQuality of the case's dynamic bodies (a projectile case has its own per side).
    pub quality: u32,
}

impl Setting {
    /// The plane and object defaults: 60 Hz, SolverIterations 4, HitBoxQuality 1.
    pub const DEFAULT: Setting = Setting {
        tick_rate: 60.0,
        iterations: 4,
        quality: 1,
    };
    /// The stronger setting the report compares with: 240 Hz, 16 iterations, quality 32.
    pub const STRONG: Setting = Setting {
        tick_rate: 240.0,
        iterations: 16,
        quality: 32,
    };

    pub fn label(&self) -> String {
        format!(
            "{} Hz, {} it, q{}",
            self.tick_rate, self.iterations, self.quality
        )
    }

    /// The setting moved one notch toward the defaults (for shrinking).
    pub(crate) fn simpler(&self) -> Vec<Setting> {
        let mut v = Vec::new();
        if self.tick_rate != 60.0 {
            v.push(Setting {
                tick_rate: 60.0,
                ..*self
            });
        }
        if self.iterations != 4 {
            v.push(Setting {
                iterations: 4,
                ..*self
            });
        }
        if self.quality != 1 {
            v.push(Setting {
                quality: 1,
                ..*self
            });
            if self.quality > 2 {
                v.push(Setting {
                    quality: self.quality / 2,
                    ..*self
                });
            }
        }
        v
    }
}

/// Ranges of the solver knobs.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct SettingRanges {
    /// Ticks per second, log-uniform.
    pub tick_rate: Span,
    /// SolverIterations, inclusive.
    pub iterations: (u32, u32),
    /// HitBoxQuality, inclusive.
    pub quality: (u32, u32),
}
