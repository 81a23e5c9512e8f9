//! How a row judged on a noisy machine is measured: the named estimators (see
//! docs/benchmarks.md), and the runner of interleaved blocks most of them use.
//!
//! Wall-clock figures on a shared machine swing by 2× when other work runs: a row is only as
//! good as the way its samples are reduced. Each row of a report names its [`Estimator`]
//! (`estimator` in the JSON, in brackets in the goal's text):
//!
//! - the two sides of a comparison (A and B) run in short blocks, interleaved (A B B A ...),
//!   so slow stretches of the machine fall on both sides;
//! - each block yields a figure per tick: wall time, and the CPU time of every process
//!   involved (this one and the daemons, nanosecond counters from /proc), which other
//!   processes' load barely moves;
//! - a side's figure is the minimum (the least disturbed block) or the median of its blocks.

use std::time::Instant;

use crate::error::{BenchError, BenchResult};
use crate::procfs::{own_cpu_ns, ThreadsCpu};
use crate::stats::median;

/// A named way of reducing measurements to a row's figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Estimator {
    CpuMedianOfBlocks,
    CpuMinOfBlocks,
    WallMedianOfBlocks,
    WallMinOfBlocks,
    StepInProcess,
    WallP99MinOfBlocks,
    RateSlowestPlane,
    WallMedianOfSamples,
    WallP99OfSamples,
    CpuOverWindow,
}

impl Estimator {
    /// Every estimator, in the order the documentation lists them.
    pub const ALL: [Estimator; 10] = [
        Estimator::CpuMedianOfBlocks,
        Estimator::CpuMinOfBlocks,
        Estimator::WallMedianOfBlocks,
        Estimator::WallMinOfBlocks,
        Estimator::StepInProcess,
        Estimator::WallP99MinOfBlocks,
        Estimator::RateSlowestPlane,
        Estimator::WallMedianOfSamples,
        Estimator::WallP99OfSamples,
        Estimator::CpuOverWindow,
    ];

    /// The stable short name rows carry.
    pub fn name(self) -> &'static str {
        match self {
            Estimator::CpuMedianOfBlocks => "cpu-median-of-blocks",
            Estimator::CpuMinOfBlocks => "cpu-min-of-blocks",
            Estimator::WallMedianOfBlocks => "wall-median-of-blocks",
            Estimator::WallMinOfBlocks => "wall-min-of-blocks",
            Estimator::StepInProcess => "step-in-process",
            Estimator::WallP99MinOfBlocks => "wall-p99-min-of-blocks",
            Estimator::RateSlowestPlane => "rate-slowest-plane",
            Estimator::WallMedianOfSamples => "wall-median-of-samples",
            Estimator::WallP99OfSamples => "wall-p99-of-samples",
            Estimator::CpuOverWindow => "cpu-over-window",
        }
    }

    /// What the name means, in one line.
    pub fn meaning(self) -> &'static str {
        match self {
            Estimator::CpuMedianOfBlocks => {
                "CPU time per tick of both processes (daemon and client, ns counters of \
                 /proc/PID/task/*/schedstat and the client's own process clock; a client that \
                 only watches planes ticking on their timers is left out), blocks of A and B \
                 interleaved, the median of each side's blocks"
            }
            Estimator::CpuMinOfBlocks => {
                "the same CPU time per tick of both processes, the minimum of each side's \
                 blocks"
            }
            Estimator::WallMedianOfBlocks => {
                "wall time per tick, blocks of A and B interleaved, the median of each side's \
                 blocks"
            }
            Estimator::WallMinOfBlocks => {
                "wall time per tick, blocks of A and B interleaved, the minimum of each side's \
                 blocks (its least disturbed block)"
            }
            Estimator::StepInProcess => {
                "wall time of the plane's step alone, the daemon's plane code stepped in this \
                 process (no client, no IPC), blocks of A and B interleaved, the minimum of \
                 each side's blocks (medians reported beside)"
            }
            Estimator::WallP99MinOfBlocks => {
                "the p99 of the request wall times within each block, blocks of A and B \
                 interleaved, the minimum of each side's blocks"
            }
            Estimator::RateSlowestPlane => {
                "ticks each plane made over a block (tick counters of its headers) / the \
                 block's wall time, the slowest plane of each block, the median of the blocks"
            }
            Estimator::WallMedianOfSamples => {
                "the median of per-sample wall times in one run (latencies, not comparisons \
                 of two sides)"
            }
            Estimator::WallP99OfSamples => "the p99 of per-sample wall times in one run",
            Estimator::CpuOverWindow => {
                "a process's CPU time over a window (schedstat ns counters) / the window's \
                 wall time"
            }
        }
    }

    /// `[name]`, as goal texts end.
    pub fn tag(self) -> String {
        format!("[{}]", self.name())
    }

    /// The figure of one side under this estimator (`None` for estimators not made of
    /// blocks of wall and CPU).
    pub fn of(self, side: &Side) -> Option<f64> {
        match self {
            Estimator::CpuMedianOfBlocks => Some(side.cpu_us.median),
            Estimator::CpuMinOfBlocks => Some(side.cpu_us.min),
            Estimator::WallMedianOfBlocks => Some(side.wall_us.median),
            Estimator::WallMinOfBlocks | Estimator::StepInProcess => Some(side.wall_us.min),
            _ => None,
        }
    }
}

impl serde::Serialize for Estimator {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// Every estimator with its meaning, as reports store them (`estimators` in the JSON).
pub fn glossary() -> std::collections::BTreeMap<&'static str, &'static str> {
    Estimator::ALL
        .into_iter()
        .map(|e| (e.name(), e.meaning()))
        .collect()
}

/// A goal row as the reports store it: the goal, what was measured, the verdict, and the
/// estimator that judged it. Serialised with the fields of [`crate::report::Goal`] plus
/// `estimator`, so the pages read it as a goal.
#[derive(Debug, Clone, serde::Serialize)]
pub struct JudgedGoal {
    pub goal: String,
    pub value: String,
    pub met: Option<bool>,
    pub estimator: Estimator,
}

impl JudgedGoal {
    /// A goal judged by `estimator`; its text ends with the estimator's name in brackets.
    pub fn new(
        estimator: Estimator,
        goal: impl Into<String>,
        value: impl Into<String>,
        met: Option<bool>,
    ) -> JudgedGoal {
        JudgedGoal {
            goal: format!("{} {}", goal.into(), estimator.tag()),
            value: value.into(),
            met,
            estimator,
        }
    }
}

/// What one block measured, per tick (or per request, per frame: the block's unit).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Block {
    /// Wall time per tick, µs.
    pub wall_us: f64,
    /// CPU time per tick of every process the block involves, µs.
    pub cpu_us: f64,
}

/// The smallest and the median of a side's blocks.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct MinMedian {
    pub min: f64,
    pub median: f64,
}

impl MinMedian {
    /// Of `values` (NaNs ignored); `None` when there is none.
    pub fn of(values: &[f64]) -> Option<MinMedian> {
        let min = values
            .iter()
            .copied()
            .filter(|v| !v.is_nan())
            .fold(f64::INFINITY, f64::min);
        Some(MinMedian {
            min: min.is_finite().then_some(min)?,
            median: median(values)?,
        })
    }
}

/// One side's blocks.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Side {
    pub blocks: Vec<Block>,
    pub wall_us: MinMedian,
    pub cpu_us: MinMedian,
}

impl Side {
    /// The figures of `blocks`; `None` when there is none.
    pub fn of(blocks: Vec<Block>) -> Option<Side> {
        let wall: Vec<f64> = blocks.iter().map(|b| b.wall_us).collect();
        let cpu: Vec<f64> = blocks.iter().map(|b| b.cpu_us).collect();
        Some(Side {
            wall_us: MinMedian::of(&wall)?,
            cpu_us: MinMedian::of(&cpu)?,
            blocks,
        })
    }
}

/// In which order the blocks of the two sides run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Order {
    /// A B B A A B B A ...: each side as often first as second, so a trend in the machine's
    /// load (or in the scene) weighs on both sides alike, where A B A B ... would favour B.
    Abba,
}

impl Order {
    /// Whether block `i` of the sequence (0, 1, 2, ...) is A's.
    pub fn is_a(self, i: usize) -> bool {
        match self {
            Order::Abba => matches!(i % 4, 0 | 3),
        }
    }
}

/// Two sides measured in interleaved blocks: their blocks and their figures.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Pair {
    pub order: Order,
    pub a: Side,
    pub b: Side,
}

impl Pair {
    /// A's figure over B's under `estimator` (`None` when it is not a block estimator).
    pub fn ratio(&self, estimator: Estimator) -> Option<f64> {
        Some(estimator.of(&self.a)? / estimator.of(&self.b)?)
    }

    /// The four ratios A / B: wall and CPU, of the minima and of the medians.
    pub fn ratios(&self) -> Ratios {
        Ratios {
            wall_min: self.a.wall_us.min / self.b.wall_us.min,
            wall_median: self.a.wall_us.median / self.b.wall_us.median,
            cpu_min: self.a.cpu_us.min / self.b.cpu_us.min,
            cpu_median: self.a.cpu_us.median / self.b.cpu_us.median,
        }
    }
}

/// A over B under each block estimator.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Ratios {
    pub wall_min: f64,
    pub wall_median: f64,
    pub cpu_min: f64,
    pub cpu_median: f64,
}

/// Runs `blocks` blocks of each side in `order` (A first) and returns both sides' blocks
/// with their minima and medians. `a` and `b` each run one block and return its figures
/// (see [`timed`]). Fails when `blocks` is 0 or a block fails.
pub fn interleaved<A, B>(blocks: usize, order: Order, mut a: A, mut b: B) -> BenchResult<Pair>
where
    A: FnMut() -> BenchResult<Block>,
    B: FnMut() -> BenchResult<Block>,
{
    let (mut of_a, mut of_b) = (Vec::with_capacity(blocks), Vec::with_capacity(blocks));
    for i in 0..2 * blocks {
        if order.is_a(i) {
            of_a.push(a()?);
        } else {
            of_b.push(b()?);
        }
    }
    let none = || BenchError::Failed("interleaved blocks: no block was measured".into());
    Ok(Pair {
        order,
        a: Side::of(of_a).ok_or_else(none)?,
        b: Side::of(of_b).ok_or_else(none)?,
    })
}

/// The CPU clocks of a block: this process (all its threads) and the given other
/// processes (every thread, from /proc).
#[derive(Debug, Clone)]
pub struct CpuClock {
    own: bool,
    pids: Vec<u32>,
}

/// A reading of a [`CpuClock`].
#[derive(Debug, Clone)]
pub struct CpuReading {
    own_ns: u64,
    others: Vec<ThreadsCpu>,
}

impl CpuClock {
    /// This process and `others` (daemons' process ids).
    pub fn new(others: &[u32]) -> CpuClock {
        CpuClock {
            own: true,
            pids: others.to_vec(),
        }
    }

    /// `pids` alone: for blocks in which this process only watches (reads headers of planes
    /// ticking on their timers) and its CPU is the measurement's, not the work's.
    pub fn daemons_only(pids: &[u32]) -> CpuClock {
        CpuClock {
            own: false,
            pids: pids.to_vec(),
        }
    }

    pub fn read(&self) -> BenchResult<CpuReading> {
        Ok(CpuReading {
            own_ns: if self.own { own_cpu_ns() } else { 0 },
            others: self
                .pids
                .iter()
                .map(|&p| ThreadsCpu::of(p))
                .collect::<BenchResult<_>>()?,
        })
    }
}

impl CpuReading {
    /// CPU nanoseconds of all the clock's processes since `before`.
    pub fn used_since(&self, before: &CpuReading) -> u64 {
        let others: u64 = self
            .others
            .iter()
            .zip(&before.others)
            .map(|(now, then)| now.used_since(then))
            .sum();
        self.own_ns.saturating_sub(before.own_ns) + others
    }
}

/// Runs one block, `work`, which returns how many ticks it made; returns its wall and the
/// CPU of `clock`'s processes per tick. Fails when `work` made no tick.
pub fn timed(clock: &CpuClock, work: impl FnOnce() -> BenchResult<usize>) -> BenchResult<Block> {
    let cpu0 = clock.read()?;
    let started = Instant::now();
    let ticks = work()?;
    let wall = started.elapsed();
    let cpu = clock.read()?.used_since(&cpu0);
    if ticks == 0 {
        return Err(BenchError::Failed("a timed block made no tick".into()));
    }
    Ok(Block {
        wall_us: wall.as_secs_f64() * 1e6 / ticks as f64,
        cpu_us: cpu as f64 / 1e3 / ticks as f64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_read_back() {
        for e in Estimator::ALL {
            assert!(!e.meaning().is_empty());
            assert_eq!(e.tag(), format!("[{}]", e.name()));
            assert_eq!(serde_json::to_value(e).unwrap(), e.name());
        }
        let mut names: Vec<_> = Estimator::ALL.iter().map(|e| e.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Estimator::ALL.len());
        assert_eq!(glossary().len(), Estimator::ALL.len());
        let g = JudgedGoal::new(Estimator::CpuMinOfBlocks, "x ≤ 1", "0.9", Some(true));
        assert_eq!(g.goal, "x ≤ 1 [cpu-min-of-blocks]");
        let json = serde_json::to_value(&g).unwrap();
        assert_eq!(json["estimator"], "cpu-min-of-blocks");
        // The pages read it as a goal.
        let read: crate::report::Goal = serde_json::from_value(json).unwrap();
        assert_eq!((read.value.as_str(), read.met), ("0.9", Some(true)));
    }

    #[test]
    fn blocks_interleave_in_the_order_asked() {
        let seq: String = (0..8)
            .map(|i| if Order::Abba.is_a(i) { 'A' } else { 'B' })
            .collect();
        assert_eq!(seq, "ABBAABBA");
        let log = std::cell::RefCell::new(String::new());
        let mut n = 0.0;
        let pair = interleaved(
            3,
            Order::Abba,
            || {
                log.borrow_mut().push('A');
                n += 1.0;
                Ok(Block {
                    wall_us: 10.0 * n,
                    cpu_us: 1.0,
                })
            },
            || {
                log.borrow_mut().push('B');
                Ok(Block {
                    wall_us: 5.0,
                    cpu_us: 2.0,
                })
            },
        )
        .unwrap();
        assert_eq!(*log.borrow(), "ABBAAB");
        assert_eq!(pair.a.blocks.len(), 3);
        assert_eq!(pair.b.blocks.len(), 3);
        assert_eq!(
            pair.a.wall_us,
            MinMedian {
                min: 10.0,
                median: 20.0
            }
        );
        let r = pair.ratios();
        assert_eq!((r.wall_min, r.wall_median), (2.0, 4.0));
        assert_eq!((r.cpu_min, r.cpu_median), (0.5, 0.5));
        assert_eq!(pair.ratio(Estimator::WallMinOfBlocks), Some(2.0));
        assert_eq!(pair.ratio(Estimator::CpuMedianOfBlocks), Some(0.5));
        assert_eq!(pair.ratio(Estimator::WallMedianOfSamples), None);
    }

    #[test]
    fn no_blocks_or_a_failed_block_is_an_error_not_a_panic() {
        let ok = || {
            Ok(Block {
                wall_us: 1.0,
                cpu_us: 1.0,
            })
        };
        assert!(interleaved(0, Order::Abba, ok, ok).is_err());
        let fail = || Err(BenchError::Failed("broken".into()));
        assert!(interleaved(2, Order::Abba, ok, fail).is_err());
        assert_eq!(MinMedian::of(&[]), None);
        assert_eq!(MinMedian::of(&[f64::NAN]), None);
        assert_eq!(
            MinMedian::of(&[3.0, f64::NAN, 1.0, 2.0]),
            Some(MinMedian {
                min: 1.0,
                median: 2.0
            })
        );
    }

    #[test]
    fn a_timed_block_counts_wall_and_cpu_per_tick() {
        let clock = CpuClock::new(&[std::process::id()]);
        let block = timed(&clock, || {
            crate::procfs::burn(20_000_000);
            Ok(4)
        })
        .unwrap();
        // This thread burnt 20 ms over 4 ticks, counted twice (the process's own clock and
        // its threads through /proc): at least 10,000 µs of CPU a tick; its wall at least
        // the 5,000 µs a tick one thread needs for 20 ms of CPU.
        assert!(block.cpu_us >= 10_000.0, "{block:?}");
        assert!(block.wall_us >= 5_000.0, "{block:?}");
        assert!(timed(&clock, || Ok(0)).is_err());
    }
}
