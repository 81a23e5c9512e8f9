//! The plane's tallies over its objects' parts: objects per HitBoxQuality (the plane-wide
//! solver scales with the highest), objects with a drive of their own, and mesh vertices
//! (for quotas). Kept in step by the ops that add, change and remove parts.

use shm_layout::validate::MAX_HIT_BOX_QUALITY;

/// What the tallies keep across ticks (snapshot state, in this order); the per-quality
/// counts are rebuilt from the parts.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct Kept {
    /// Objects with a drive of their own (ImpulseDirection, ConstantForce, RotateTo, SetPin).
    driven: u32,
    /// Mesh vertices of all parts (for quotas).
    mesh_vertices: u64,
}

impl Kept {
    /// Mesh vertices of all parts.
    pub(crate) fn mesh_vertices(&self) -> u64 {
        self.mesh_vertices
    }
}

/// The plane's tallies (see the module doc).
#[derive(Debug)]
pub(crate) struct Tally {
    /// What is kept across ticks (snapshot state).
    pub(crate) kept: Kept,
    /// Objects per HitBoxQuality value.
    qualities: [u32; MAX_HIT_BOX_QUALITY as usize + 1],
}

impl Default for Tally {
    fn default() -> Self {
        Tally {
            kept: Kept::default(),
            qualities: [0; MAX_HIT_BOX_QUALITY as usize + 1],
        }
    }
}

impl Tally {
    /// A part of `quality` with `mesh_vertices` joined the plane.
    pub(crate) fn add(&mut self, quality: u32, mesh_vertices: u64) {
        self.qualities[quality as usize] += 1;
        self.kept.mesh_vertices += mesh_vertices;
    }

    /// A part of `quality` with `mesh_vertices`, `driven` or not, left the plane.
    pub(crate) fn remove(&mut self, quality: u32, mesh_vertices: u64, driven: bool) {
        self.qualities[quality as usize] -= 1;
        self.kept.mesh_vertices -= mesh_vertices;
        if driven {
            self.kept.driven -= 1;
        }
    }

    /// A part's HitBoxQuality went from `before` to `after`.
    pub(crate) fn requalify(&mut self, before: u32, after: u32) {
        if before != after {
            self.qualities[before as usize] -= 1;
            self.qualities[after as usize] += 1;
        }
    }

    /// A part gained (`on`) or lost a drive of its own.
    pub(crate) fn count_driven(&mut self, on: bool) {
        match on {
            true => self.kept.driven += 1,
            false => self.kept.driven -= 1,
        }
    }

    /// Objects with a drive of their own.
    pub(crate) fn driven(&self) -> u32 {
        self.kept.driven
    }

    /// Mesh vertices of all parts.
    pub(crate) fn mesh_vertices(&self) -> u64 {
        self.kept.mesh_vertices
    }

    /// The highest HitBoxQuality of any object (1 without objects).
    pub(crate) fn max_quality(&self) -> u32 {
        (1..=MAX_HIT_BOX_QUALITY)
            .rev()
            .find(|q| self.qualities[*q as usize] > 0)
            .unwrap_or(1)
    }

    /// Counts the objects per quality again from every part's `qualities` (after a restore).
    pub(crate) fn recount_qualities(&mut self, qualities: impl Iterator<Item = u32>) {
        self.qualities = [0; MAX_HIT_BOX_QUALITY as usize + 1];
        for q in qualities {
            self.qualities[q as usize] += 1;
        }
    }
}
