//! What the recording tests share: a temporary folder, a file removed at the end, the
//! hashes a recording holds and a replay to its end.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use client_sdk::{Advanced, Client, Recording, Replay};
use integration_tests::unique_domain;
use shm_layout::recording::Event;

/// A folder of its own under the temporary folder, removed when dropped.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> TempDir {
        let path = std::env::temp_dir().join(unique_domain(tag));
        std::fs::create_dir_all(&path).expect("create a temporary folder");
        TempDir(path)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }

    pub fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// (tick, state hash) of every `Tick` entry of `recording`.
pub fn file_hashes(recording: &Recording) -> Vec<(u64, u64)> {
    recording
        .events
        .iter()
        .filter_map(|e| match e {
            Event::Tick {
                tick, state_hash, ..
            } => Some((*tick, *state_hash)),
            _ => None,
        })
        .collect()
}

/// Replays `recording` on `client` one tick at a time to its end (a divergence fails the
/// test naming it): (tick, state hash) of every tick as the replayed plane published it,
/// and the replay.
pub fn replay_to_end(client: &Client, recording: &Arc<Recording>) -> (Vec<(u64, u64)>, Replay) {
    let mut replay = Replay::start(client, recording.clone()).expect("start the replay");
    let mut seen = Vec::new();
    loop {
        match replay.advance().expect("advance the replay") {
            Advanced::Tick(tick) => {
                assert_eq!(replay.tick(), tick);
                seen.push((tick, replay.plane().state_hash().unwrap()));
            }
            Advanced::End => break,
            Advanced::Diverged(d) => panic!("after {} tick(s): {d}", seen.len()),
        }
    }
    assert!(replay.at_end());
    (seen, replay)
}

/// Removes a file when dropped (one the daemon named in its own folder).
pub struct RemoveOnDrop(pub PathBuf);

impl Drop for RemoveOnDrop {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}
