//! Building blocks of `physics-bench`, shared by its subcommands.
//!
//! - [`daemon`]: real daemon processes in throw-away domains.
//! - [`procfs`]: CPU time, RSS and shared-memory size of a process / domain.
//! - [`scene`]: the benchmark scenes, built identically in the daemon and in process.
//! - [`stats`]: medians and percentiles.
//! - [`progress`]: the progress bar and its log lines.
//! - [`report`]: writing the JSON and markdown reports.
//! - [`ipc`]: the `ipc` subcommand (daemon overhead, delivery, requests, idle, memory).
//! - [`sim`]: an in-process plane stepped at a fixed dt with its step time accumulated.
//! - [`accuracy`]: the `accuracy` subcommand (error against run time).
//! - [`stability`]: the `stability` subcommand (stiff and extreme scenes, pass/fail).

pub mod accuracy;
pub mod daemon;
pub mod error;
pub mod ipc;
pub mod procfs;
pub mod progress;
pub mod report;
pub mod scene;
pub mod sim;
pub mod stability;
pub mod stats;
