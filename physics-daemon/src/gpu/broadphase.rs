//! The GPU broadphase: a uniform grid hashed into a table of `T` buckets (a power of two, at
//! least twice the body capacity), rebuilt every substep in four passes over the bodies:
//!
//! 1. `count`: each hashed body adds one to its cell's bucket (atomics);
//! 2. an exclusive prefix sum of the bucket counts (`scan.wgsl`, blocks of 512, recursively
//!    over the block totals: three levels cover 2^27 buckets) gives each bucket its first
//!    index;
//! 3. `scatter`: each body takes the next index of its bucket (atomics on a copy of the
//!    starts) and writes an entry there, its id and its cell, so the entries are sorted by
//!    bucket;
//! 4. `solve` / `pairs`: each body visits its 27 neighbour cells and tests the bodies whose
//!    entries name one of those cells. A cell's bucket is its x plus a hash of its row
//!    (y, z), so the three cells of a row are consecutive buckets and one run of entries:
//!    9 runs per body, and a body that only shares a bucket is skipped by its entry, without
//!    reading its state (on lavapipe those scattered reads fell out of L2 at 40k bodies:
//!    docs/gpu.md, "Scaling").
//!
//! The cell size is the largest full extent of any dynamic collidable body, so two touching
//! bodies are never more than one cell apart. Anchored bodies larger than a cell (floors,
//! walls) are not hashed: they sit in a short "large" list that every body tests. Every step
//! is O(N) in the body count; [`PairMode::BruteForce`] tests every pair instead (O(N²)), for
//! the benchmark and the property test.

/// Which candidate pairs the solver and the pair list test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PairMode {
    /// The spatial hash (the default).
    #[default]
    Hash,
    /// Every pair (O(N²)).
    BruteForce,
}

/// Elements one `scan_blocks` workgroup scans.
pub(crate) const SCAN_BLOCK: u32 = 512;

/// Bucket count for a body capacity: a power of two, at least twice the capacity.
pub(crate) fn table_size(capacity: usize) -> u32 {
    (2 * capacity).next_power_of_two().max(1024) as u32
}

/// Lengths of the arrays the prefix sum scans, level by level: `T`, then the block totals of
/// each level until one block holds them all.
pub(crate) fn scan_levels(table: u32) -> Vec<u32> {
    let mut levels = vec![table];
    while *levels.last().unwrap() > SCAN_BLOCK {
        let len = *levels.last().unwrap();
        levels.push(len.div_ceil(SCAN_BLOCK));
    }
    levels
}

/// Cell size and large bodies for bodies of the given full extents: `extents` yields
/// `(slot, full extent, dynamic)` of every live collidable body.
pub(crate) fn grid(extents: impl Iterator<Item = (u32, f32, bool)> + Clone) -> (f32, Vec<u32>) {
    let cell = extents
        .clone()
        .filter(|e| e.2)
        .map(|e| e.1)
        .fold(0.0f32, f32::max);
    let cell = if cell > 0.0 { cell } else { 1.0 };
    let large = extents.filter(|e| e.1 > cell).map(|e| e.0).collect();
    (cell, large)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_levels_end_in_one_block() {
        assert_eq!(scan_levels(1024), vec![1024, 2]);
        assert_eq!(scan_levels(1 << 21), vec![1 << 21, 4096, 8]);
        assert_eq!(table_size(1000), 2048);
        assert_eq!(table_size(10), 1024);
    }

    #[test]
    fn grid_takes_the_largest_dynamic_body() {
        let bodies = [
            (0, 1.0, true),
            (1, 2.0, true),
            (2, 50.0, false),
            (3, 1.5, false),
        ];
        let (cell, large) = grid(bodies.iter().copied());
        assert_eq!(cell, 2.0);
        assert_eq!(large, vec![2]);
    }
}
