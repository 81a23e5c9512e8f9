//! Recording ops: a valid start names no path (the daemon puts the file in its recordings
//! folder) or stops; a wild start names a path the daemon must refuse by name and leave
//! untouched: relative, in a folder that does not exist, an existing file or folder, a
//! NUL byte, 10,000 characters.

use shm_layout::{PlaneOp, RecordOp};

use super::Gen;

/// Paths a start must refuse (none of them is created or written).
const REFUSED: [&str; 7] = [
    "relative.physrec",
    "/nonexistent-physics-fuzz-folder/x.physrec",
    "/tmp",
    "/",
    "/dev/null",
    "/proc/self/mem",
    "/tmp/nul\0.physrec",
];

impl Gen<'_> {
    /// A recording start or stop.
    pub(super) fn record_op(&mut self, wild: bool) -> PlaneOp {
        if !self.rng.chance(0.5) {
            return PlaneOp::Record(RecordOp::Stop);
        }
        let path = match wild {
            false => String::new(),
            true if self.rng.chance(0.1) => "/".to_string() + &"a".repeat(10_000),
            true => self.rng.pick(&REFUSED).to_string(),
        };
        PlaneOp::Record(RecordOp::Start { path })
    }
}
