//! A case of any family ([`Case`]): drawn, run, judged ([`judge`]), made simpler and
//! shrunk ([`shrink`]), written out as a Luau repro.

use crate::families::{chain, drop, pile, projectile, spring, stack};
use crate::oracle::{Outcome, Violation};
use crate::rng::Rng;
use crate::space;

/// A case of any family.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[serde(tag = "family")]
pub enum Case {
    Stack(stack::Stack),
    Chain(chain::Chain),
    Projectile(projectile::Projectile),
    Drop(drop::Drop),
    Spring(spring::Spring),
    Pile(pile::Pile),
}

/// The family names, in drawing order.
pub const FAMILIES: [&str; 6] = ["stack", "chain", "projectile", "drop", "spring", "pile"];

impl Case {
    pub fn family(&self) -> &'static str {
        match self {
            Case::Stack(_) => "stack",
            Case::Chain(_) => "chain",
            Case::Projectile(_) => "projectile",
            Case::Drop(_) => "drop",
            Case::Spring(_) => "spring",
            Case::Pile(_) => "pile",
        }
    }

    /// Draws a case of family number `family` (an index into [`FAMILIES`]) from `space`.
    pub fn draw(family: usize, rng: &mut Rng, space: &space::Space) -> Case {
        match family % FAMILIES.len() {
            0 => Case::Stack(stack::Stack::draw(rng, &space.stack)),
            1 => Case::Chain(chain::Chain::draw(rng, &space.chain)),
            2 => Case::Projectile(projectile::Projectile::draw(rng, &space.projectile)),
            3 => Case::Drop(drop::Drop::draw(rng, &space.drop)),
            4 => Case::Spring(spring::Spring::draw(rng, &space.spring)),
            _ => Case::Pile(pile::Pile::draw(rng, &space.pile)),
        }
    }

    /// Builds and steps the case once. A case the plane refuses to build is reported as
    /// the `builds` oracle failing.
    pub fn run(&self) -> Outcome {
        let r = match self {
            Case::Stack(c) => c.run(),
            Case::Chain(c) => c.run(),
            Case::Projectile(c) => c.run(),
            Case::Drop(c) => c.run(),
            Case::Spring(c) => c.run(),
            Case::Pile(c) => c.run(),
        };
        r.unwrap_or_else(|e| {
            eprintln!("envelope: case did not build: {e}: {self:?}");
            Outcome {
                violations: vec![Violation::new("builds", 1.0, 0.0)],
                hash: 0,
            }
        })
    }

    /// Cases one step simpler (each parameter moved toward its simplest value), for
    /// shrinking.
    pub fn simpler(&self) -> Vec<Case> {
        match self {
            Case::Stack(c) => c.simpler().into_iter().map(Case::Stack).collect(),
            Case::Chain(c) => c.simpler().into_iter().map(Case::Chain).collect(),
            Case::Projectile(c) => c.simpler().into_iter().map(Case::Projectile).collect(),
            Case::Drop(c) => c.simpler().into_iter().map(Case::Drop).collect(),
            Case::Spring(c) => c.simpler().into_iter().map(Case::Spring).collect(),
            Case::Pile(c) => c.simpler().into_iter().map(Case::Pile).collect(),
        }
    }

    /// A runnable `physics-lua` script that builds the same scene, steps it the same way,
    /// prints the oracles' figures and raises an error when one fails.
    pub fn luau(&self) -> String {
        match self {
            Case::Stack(c) => c.luau(),
            Case::Chain(c) => c.luau(),
            Case::Projectile(c) => c.luau(),
            Case::Drop(c) => c.luau(),
            Case::Spring(c) => c.luau(),
            Case::Pile(c) => c.luau(),
        }
    }

    /// The parameters in one line.
    pub fn describe(&self) -> String {
        match self {
            Case::Stack(c) => format!("{c:?}"),
            Case::Chain(c) => format!("{c:?}"),
            Case::Projectile(c) => format!("{c:?}"),
            Case::Drop(c) => format!("{c:?}"),
            Case::Spring(c) => format!("{c:?}"),
            Case::Pile(c) => format!("{c:?}"),
        }
    }
}

/// Runs `case` and judges it: its family's oracles, `finite`, and (when `determinism`)
/// a second run whose state-hash fold must equal the first's.
pub fn judge(case: &Case, determinism: bool) -> Vec<Violation> {
    let first = case.run();
    let mut v = first.violations;
    if determinism {
        let second = case.run();
        if second.hash != first.hash {
            v.push(Violation::new("deterministic", 1.0, 0.0));
        }
    }
    v
}

/// Greedy shrinking: repeatedly takes the first simpler case that still fails `oracle`,
/// until none does or `budget` runs are spent.
pub fn shrink(case: &Case, oracle: &'static str, budget: usize) -> (Case, Vec<Violation>, usize) {
    let determinism = oracle == "deterministic";
    let mut best = case.clone();
    let mut best_v = judge(&best, determinism);
    let mut runs = 1;
    'outer: while runs < budget {
        for cand in best.simpler() {
            if runs >= budget {
                break 'outer;
            }
            runs += 1;
            let v = judge(&cand, determinism);
            if v.iter().any(|x| x.oracle == oracle) {
                best = cand;
                best_v = v;
                continue 'outer;
            }
        }
        break;
    }
    (best, best_v, runs)
}
