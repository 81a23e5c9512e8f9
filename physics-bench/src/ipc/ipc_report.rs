//! What `ipc` reports (ipc.json), which the markdown renders.

use std::collections::BTreeMap;

use super::idle::IdleCpu;
use super::lua::LuaReads;
use super::many_planes::ManyPlanes;
use super::plan::Plan;
use super::planes::{HeadOfLine, MultiPlane};
use super::scene_run::{Delivery, Memory, Overhead, Requests};
use super::threads::Threads;
use crate::estimator::JudgedGoal;
use crate::scene::Kind;
use crate::stats::Spread;

/// Figures of one scene size, per scene kind.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SizeReport {
    pub bodies: usize,
    pub overhead_ratio: BTreeMap<Kind, f64>,
    pub delivery: BTreeMap<Kind, Delivery>,
    /// Tick times behind the ratio.
    pub ticks: BTreeMap<Kind, Overhead>,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct IpcReport {
    pub quick: bool,
    pub plan: Plan,
    pub method: BTreeMap<&'static str, &'static str>,
    pub scenes: Vec<SizeReport>,
    pub round_trip_us: Spread,
    pub batched_writes_per_s: f64,
    pub requests: Requests,
    /// Threads = 2 against 1, one entry per scene (see `threads`).
    pub threads: Vec<Threads>,
    pub head_of_line: HeadOfLine,
    pub multi_plane: MultiPlane,
    pub lua: LuaReads,
    pub idle_cpu_percent: IdleCpu,
    pub memory: Vec<Memory>,
    /// The goals, each with the estimator that judged it.
    pub goals: Vec<JudgedGoal>,
    /// Every estimator's name and meaning.
    pub estimators: BTreeMap<&'static str, &'static str>,
    pub cpus: usize,
    pub seconds: f64,
    /// 100 planes × 1,000 bodies at 60 Hz against one plane of 100,000, and 10 planes on
    /// time (see `many_planes`).
    pub many_planes: ManyPlanes,
}
