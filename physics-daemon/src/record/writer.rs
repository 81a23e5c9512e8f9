//! The thread that writes one recording's file: the plane's thread hands it whole entries
//! (one message per tick) and keyframes (a copy of the state, encoded here, off the tick),
//! so a tick pays for a channel send, never for the disk.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;

use shm_layout::recording::{push_end, push_keyframe, KeyframeWhy};
use shm_layout::{CommandError, ErrorKind};

use crate::backend::SnapshotJob;

/// What the plane's thread sends.
pub(super) enum Chunk {
    /// Entries, framed already.
    Entries(Vec<u8>),
    /// A keyframe whose snapshot is encoded here.
    Later(KeyframeWhy, SnapshotJob),
    /// The last entry; the answer is the file's length.
    End(String, Sender<Result<u64, String>>),
}

/// A recording's writer thread and the way to it.
pub(super) struct Writer {
    tx: Sender<Chunk>,
    thread: Option<JoinHandle<()>>,
    /// Set by the thread when writing failed (the recording then stops at the next tick).
    pub failed: Arc<AtomicBool>,
    /// Set by the thread when the file reached its most bytes: what comes after is not
    /// written (but the end entry), and the recording stops at the next tick.
    pub full: Arc<AtomicBool>,
    path: PathBuf,
}

impl Writer {
    /// Starts the thread writing to `file` (at `path`), which holds nothing yet.
    pub fn start(
        file: File,
        path: PathBuf,
        plane: u32,
        max_bytes: u64,
    ) -> Result<Writer, CommandError> {
        let (tx, rx) = channel::<Chunk>();
        let failed = Arc::new(AtomicBool::new(false));
        let flag = failed.clone();
        let full = Arc::new(AtomicBool::new(false));
        let full_flag = full.clone();
        let shown = path.display().to_string();
        let thread = std::thread::Builder::new()
            .name(format!("record-{plane}"))
            .spawn(move || {
                let mut out = BufWriter::with_capacity(256 * 1024, file);
                let mut written: u64 = 0;
                let mut error: Option<String> = None;
                let mut put = |bytes: &[u8], error: &mut Option<String>, last: bool| {
                    if error.is_some() {
                        return;
                    }
                    // Once full, nothing more but the end: the file stays whole up to there.
                    if !last
                        && (full_flag.load(Ordering::SeqCst)
                            || written + bytes.len() as u64 > max_bytes)
                    {
                        full_flag.store(true, Ordering::SeqCst);
                        return;
                    }
                    match out.write_all(bytes) {
                        Ok(()) => written += bytes.len() as u64,
                        Err(e) => {
                            *error = Some(format!("writing recording {shown}: {e}"));
                            flag.store(true, Ordering::SeqCst);
                        }
                    }
                };
                for chunk in rx {
                    match chunk {
                        Chunk::Entries(bytes) => put(&bytes, &mut error, false),
                        Chunk::Later(why, job) => match job() {
                            Ok(snapshot) => {
                                let mut entry = Vec::with_capacity(snapshot.len() + 16);
                                push_keyframe(&mut entry, why, &snapshot);
                                put(&entry, &mut error, false);
                            }
                            Err(e) => {
                                error = Some(format!("a keyframe of {shown}: {}", e.message));
                                flag.store(true, Ordering::SeqCst);
                            }
                        },
                        Chunk::End(reason, done) => {
                            let mut entry = Vec::new();
                            push_end(&mut entry, &reason);
                            put(&entry, &mut error, true);
                            if error.is_none() {
                                if let Err(e) = out.flush().and_then(|_| out.get_ref().sync_data())
                                {
                                    error = Some(format!("writing recording {shown}: {e}"));
                                }
                            }
                            let _ = done.send(match error.take() {
                                None => Ok(written),
                                Some(e) => Err(e),
                            });
                            return;
                        }
                    }
                }
                // The plane went without an end (it panicked): what was written stays.
                let _ = out.flush();
            })
            .map_err(|e| {
                CommandError::new(
                    ErrorKind::Internal,
                    format!("cannot start the recording's writer thread: {e}"),
                )
            })?;
        Ok(Writer {
            tx,
            thread: Some(thread),
            failed,
            full,
            path,
        })
    }

    /// Hands `chunk` to the thread.
    pub fn send(&self, chunk: Chunk) {
        // A thread that ended has set `failed`; the recording stops at the next tick.
        let _ = self.tx.send(chunk);
    }

    /// Writes the end entry, waits until the file is on disk and gives its length.
    pub fn finish(mut self, reason: &str) -> Result<u64, CommandError> {
        let (done, answer) = channel();
        let _ = self.tx.send(Chunk::End(reason.to_owned(), done));
        let result = answer.recv().unwrap_or_else(|_| {
            Err(format!(
                "the writer of recording {} stopped",
                self.path.display()
            ))
        });
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        result.map_err(|e| CommandError::new(ErrorKind::Internal, e))
    }
}
