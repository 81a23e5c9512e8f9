//! `physics-bench peers`: scenes other engines publish figures for, measured on our side
//! with the defaults.

use std::path::PathBuf;

use super::error::{BenchError, BenchResult};

/// Options of the `peers` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct PeersArgs {
    /// Fewer steps.
    #[arg(long)]
    pub quick: bool,
    /// Folder receiving peers.json and peers.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

pub fn run(args: &PeersArgs) -> BenchResult<()> {
    let _ = args;
    Err(BenchError::Failed("peers: not built yet".into()))
}
