//! `physics-envelope`: the physics fuzzer. Scenes are drawn over parameter spaces (one
//! family per module of [`families`]), stepped in process through the daemon's own plane
//! code (`physics_scenes::LocalPlane`) and judged by oracles from physical law; each
//! failure is shrunk to a minimal case and printed as a runnable Luau repro for
//! `physics-lua`. `physics-bench envelope` runs it for a number of cases or minutes and
//! searches each family's critical value; tests/tests/envelope.rs runs a fixed seed inside
//! the documented envelope ([`space::HOLDS`]).
//!
//! Layered bottom to top (this file only declares and re-exports):
//!
//! - [`rng`]: the seeded generator and [`Span`]; [`steps`]: shrinking steps of one
//!   parameter; [`luau`]: the pieces every repro shares; [`setting`]: the solver knobs and
//!   their ranges.
//! - [`plane`]: one case's plane stepped at a fixed dt, recording non-finite bodies and the
//!   state-hash fold; [`oracle`]: violations, outcomes and the shared `finite` oracle.
//! - [`families`]: the scene families (stacks and columns, chains, projectiles, drops,
//!   springs, piles), each with its parameters and their ranges, oracles, shrinking and
//!   Luau repro.
//! - [`space`]: the parameter ranges as data: [`space::FULL`] (what the fuzzer explores)
//!   and [`space::HOLDS`] (where every oracle holds today; widened as fixes land).
//! - [`case`]: a case of any family, judged and shrunk; [`fuzz`](mod@fuzz): the fuzz run and its
//!   report; [`critical`]: the critical-value searches and the goals.
//!
//! Oracles shared by every family: every body finite after every tick (`finite`), and the
//! fold of the tick headers' `state_hash` equal across two runs of the same case
//! (`deterministic`). The others are stated in each family's module header.

pub mod case;
pub mod critical;
pub mod families;
pub mod fuzz;
pub mod luau;
pub mod oracle;
pub mod plane;
pub mod rng;
pub mod setting;
pub mod space;
pub mod steps;

pub use case::{judge, shrink, Case, FAMILIES};
pub use fuzz::{fuzz, FamilyStats, Finding, FuzzConfig, FuzzReport};
pub use luau::{luau_prelude, lv, LUAU_END};
pub use oracle::{at_least, at_most, finish, Outcome, Violation};
pub use rng::{round3, Rng, Span};
pub use setting::{Setting, SettingRanges};
pub use steps::{toward, toward_int};

/// Makes rayon's global pool one thread, as the daemon steps a Threads = 1 plane (call
/// before the first case; later calls and an already built pool are no-ops).
pub fn one_pool_thread() {
    let _ = rapier3d::rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_seed_draws_the_same_cases() {
        let draw = |seed| {
            let mut rng = Rng::new(seed);
            (0..12)
                .map(|i| Case::draw(i, &mut rng, &space::FULL))
                .collect::<Vec<_>>()
        };
        assert_eq!(draw(7), draw(7));
        assert_ne!(draw(7), draw(8));
    }

    #[test]
    fn draws_stay_inside_their_ranges() {
        let mut rng = Rng::new(3);
        for _ in 0..1000 {
            let v = rng.log_uniform(Span(0.05, 100.0));
            assert!((0.05..=100.0).contains(&v), "{v}");
            let q = rng.int_log(1, 32);
            assert!((1..=32).contains(&q), "{q}");
        }
    }

    #[test]
    fn shrinking_steps_move_toward_the_simple_value() {
        assert_eq!(toward(1000.0, 1.0), vec![1.0, 31.6]);
        assert_eq!(toward(1.0, 1.0), Vec::<f64>::new());
        assert_eq!(toward_int(20, 2), vec![2, 11]);
        assert_eq!(round3(0.813_000_000_1), 0.813);
    }
}
