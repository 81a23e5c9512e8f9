//! `physics-envelope`: the physics fuzzer. Scenes are drawn over parameter spaces (one
//! family per module of [`families`]), stepped in process through the daemon's own plane
//! code (`physics_scenes::LocalPlane`) and judged by oracles from physical law; each
//! failure is shrunk to a minimal case and printed as a runnable Luau repro for
//! `physics-lua`. `physics-bench envelope` runs it for a number of cases or minutes and
//! searches each family's critical value; tests/tests/envelope.rs runs a fixed seed inside
//! the documented envelope ([`space::HOLDS`]).
//!
//! - [`families`]: the scene families (stacks and columns, chains, projectiles, drops,
//!   springs, piles), each with its parameters, oracles, shrinking and Luau repro.
//! - [`space`]: the parameter ranges as data: [`space::FULL`] (what the fuzzer explores)
//!   and [`space::HOLDS`] (where every oracle holds today; widened as fixes land).
//! - [`plane`]: one case's plane stepped at a fixed dt, recording non-finite bodies and the
//!   state-hash fold.
//! - [`critical`]: the critical-value searches and the issue's goals.
//!
//! Oracles shared by every family: every body finite after every tick (`finite`), and the
//! fold of the tick headers' `state_hash` equal across two runs of the same case
//! (`deterministic`). The others are stated in each family's module header.

pub mod critical;
pub mod families;
pub mod plane;
pub mod space;

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use families::{chain, drop, pile, projectile, spring, stack};
use plane::Run;

/// Makes rayon's global pool one thread, as the daemon steps a Threads = 1 plane (call
/// before the first case; later calls and an already built pool are no-ops).
pub fn one_pool_thread() {
    let _ = rapier3d::rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global();
}

/// The solver knobs a case runs at (every case carries its own).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Setting {
    /// Ticks per simulated second (the plane is stepped by hand at `1 / tick_rate`).
    pub tick_rate: f32,
    pub iterations: u32,
    /// HitBoxQuality of the case's dynamic bodies (a projectile case has its own per side).
    pub quality: u32,
}

impl Setting {
    /// The plane and object defaults: 60 Hz, SolverIterations 4, HitBoxQuality 1.
    pub const DEFAULT: Setting = Setting {
        tick_rate: 60.0,
        iterations: 4,
        quality: 1,
    };
    /// The stronger setting the report compares with: 240 Hz, 16 iterations, quality 32.
    pub const STRONG: Setting = Setting {
        tick_rate: 240.0,
        iterations: 16,
        quality: 32,
    };

    pub fn label(&self) -> String {
        format!(
            "{} Hz, {} it, q{}",
            self.tick_rate, self.iterations, self.quality
        )
    }

    /// The setting moved one notch toward the defaults (for shrinking).
    fn simpler(&self) -> Vec<Setting> {
        let mut v = Vec::new();
        if self.tick_rate != 60.0 {
            v.push(Setting {
                tick_rate: 60.0,
                ..*self
            });
        }
        if self.iterations != 4 {
            v.push(Setting {
                iterations: 4,
                ..*self
            });
        }
        if self.quality != 1 {
            v.push(Setting {
                quality: 1,
                ..*self
            });
            if self.quality > 2 {
                v.push(Setting {
                    quality: self.quality / 2,
                    ..*self
                });
            }
        }
        v
    }
}

/// One oracle that did not hold: its figure against its bound.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Violation {
    pub oracle: &'static str,
    pub figure: f64,
    pub bound: f64,
}

impl Violation {
    pub fn new(oracle: &'static str, figure: f64, bound: f64) -> Violation {
        Violation {
            oracle,
            figure,
            bound,
        }
    }
}

/// What one run of a case gave.
#[derive(Debug, Clone, Default)]
pub struct Outcome {
    pub violations: Vec<Violation>,
    pub hash: u64,
}

/// Pushes a violation when `figure > bound` (or is NaN).
pub fn at_most(v: &mut Vec<Violation>, oracle: &'static str, figure: f64, bound: f64) {
    if figure.is_nan() || figure > bound {
        v.push(Violation::new(oracle, figure, bound));
    }
}

/// Pushes a violation when `figure < bound` (or is NaN).
pub fn at_least(v: &mut Vec<Violation>, oracle: &'static str, figure: f64, bound: f64) {
    if figure.is_nan() || figure < bound {
        v.push(Violation::new(oracle, figure, bound));
    }
}

/// Ends a run: adds the shared `finite` oracle.
pub fn finish(run: &Run, mut violations: Vec<Violation>) -> Outcome {
    if let Some(t) = run.non_finite_at {
        violations.insert(0, Violation::new("finite", t as f64, 0.0));
    }
    Outcome {
        violations,
        hash: run.hash,
    }
}

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

/// A failure shrunk: the case as drawn, the simplest case found that still fails the same
/// oracle, and that case's violations.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Finding {
    pub family: &'static str,
    pub oracle: &'static str,
    pub drawn: Case,
    pub shrunk: Case,
    pub violations: Vec<Violation>,
    /// Runs the shrinking took.
    pub shrink_runs: usize,
    pub luau: String,
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

/// How a fuzz run is bounded and what it draws from.
#[derive(Debug, Clone)]
pub struct FuzzConfig {
    pub seed: u64,
    /// Stop after this many cases ...
    pub cases: Option<usize>,
    /// ... or after this long (whichever comes first; one of them must be set).
    pub time: Option<Duration>,
    pub space: space::Space,
    /// Rerun every n-th case for the determinism oracle (1: every case; 0: never).
    pub determinism_every: usize,
    /// Runs each shrink may take (0: no shrinking).
    pub shrink_budget: usize,
    /// Findings shrunk per (family, oracle); later failures of the same pair are counted.
    pub shrink_per_oracle: usize,
}

/// Per family: cases run, cases failing, failures by oracle.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct FamilyStats {
    pub cases: usize,
    pub failing: usize,
    pub by_oracle: BTreeMap<&'static str, usize>,
    pub wall_s: f64,
}

/// What a fuzz run found.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FuzzReport {
    pub seed: u64,
    pub cases: usize,
    pub wall_s: f64,
    pub families: BTreeMap<&'static str, FamilyStats>,
    /// Cases in which some body turned non-finite.
    pub non_finite_cases: usize,
    pub findings: Vec<Finding>,
}

impl FuzzReport {
    pub fn failing(&self) -> usize {
        self.families.values().map(|f| f.failing).sum()
    }
}

/// Draws cases family by family in turn, judges each, and shrinks the first failures of
/// each (family, oracle). `progress` hears each case's index, family and verdict.
pub fn fuzz(cfg: &FuzzConfig, mut progress: impl FnMut(usize, &Case, &[Violation])) -> FuzzReport {
    let started = Instant::now();
    let mut rng = Rng::new(cfg.seed);
    let mut report = FuzzReport {
        seed: cfg.seed,
        cases: 0,
        wall_s: 0.0,
        families: FAMILIES
            .iter()
            .map(|f| (*f, FamilyStats::default()))
            .collect(),
        non_finite_cases: 0,
        findings: Vec::new(),
    };
    let mut shrunk: BTreeMap<(&'static str, &'static str), usize> = BTreeMap::new();
    let mut i = 0usize;
    loop {
        if cfg.cases.is_some_and(|n| i >= n) || cfg.time.is_some_and(|t| started.elapsed() >= t) {
            break;
        }
        let case = Case::draw(i, &mut rng, &cfg.space);
        let determinism = cfg.determinism_every > 0 && i.is_multiple_of(cfg.determinism_every);
        let t0 = Instant::now();
        let v = judge(&case, determinism);
        let stats = report
            .families
            .get_mut(case.family())
            .expect("every family has stats");
        stats.cases += 1;
        stats.wall_s += t0.elapsed().as_secs_f64();
        progress(i, &case, &v);
        if !v.is_empty() {
            stats.failing += 1;
            if v.iter().any(|x| x.oracle == "finite") {
                report.non_finite_cases += 1;
            }
            let mut seen = Vec::new();
            for x in &v {
                if seen.contains(&x.oracle) {
                    continue;
                }
                seen.push(x.oracle);
                *stats.by_oracle.entry(x.oracle).or_default() += 1;
            }
            // Shrink for the first oracle of this case not yet shrunk enough.
            for oracle in seen {
                let n = shrunk.entry((case.family(), oracle)).or_default();
                if *n >= cfg.shrink_per_oracle || cfg.shrink_budget == 0 {
                    continue;
                }
                *n += 1;
                let (s, sv, runs) = shrink(&case, oracle, cfg.shrink_budget);
                report.findings.push(Finding {
                    family: case.family(),
                    oracle,
                    luau: s.luau(),
                    drawn: case.clone(),
                    shrunk: s,
                    violations: sv,
                    shrink_runs: runs,
                });
                break;
            }
        }
        i += 1;
        report.cases = i;
    }
    report.wall_s = started.elapsed().as_secs_f64();
    report
}

/// A small seeded generator (SplitMix64): the same seed draws the same cases everywhere.
#[derive(Debug, Clone)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `span`.
    pub fn uniform(&mut self, span: Span) -> f64 {
        span.0 + (span.1 - span.0) * self.unit()
    }

    /// Log-uniform in `span` (both ends > 0), rounded to 3 significant digits so repros
    /// read well.
    pub fn log_uniform(&mut self, span: Span) -> f64 {
        let (a, b) = (span.0.ln(), span.1.ln());
        round3((a + (b - a) * self.unit()).exp()).clamp(span.0, span.1)
    }

    /// An integer in `lo..=hi`, log-uniform (small values as likely per octave as large).
    pub fn int_log(&mut self, lo: u32, hi: u32) -> u32 {
        let v = (lo as f64 - 0.5).max(0.5).ln()
            + ((hi as f64 + 0.5).ln() - (lo as f64 - 0.5).max(0.5).ln()) * self.unit();
        (v.exp().round() as u32).clamp(lo, hi)
    }

    /// An integer in `lo..=hi`, uniform.
    pub fn int(&mut self, lo: u32, hi: u32) -> u32 {
        lo + (self.next_u64() % (hi - lo + 1) as u64) as u32
    }

    pub fn pick<T: Copy>(&mut self, from: &[T]) -> T {
        from[(self.next_u64() % from.len() as u64) as usize]
    }
}

/// A closed range of a parameter `(lo, hi)`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Span(pub f64, pub f64);

impl Span {
    pub const fn at(v: f64) -> Span {
        Span(v, v)
    }
}

/// `v` rounded to 3 significant digits (the nearest f64 to the decimal, so it prints as
/// one).
pub fn round3(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    format!("{v:.2e}").parse().unwrap_or(v)
}

/// Shrinking steps of a positive parameter toward `simple`: the simple value itself, then
/// the geometric midpoint (3 significant digits), when different from `v`.
pub fn toward(v: f64, simple: f64) -> Vec<f64> {
    let mut out = Vec::new();
    if (v - simple).abs() > 1e-12 * simple.abs().max(1e-30) {
        out.push(simple);
        let mid = round3((v * simple).sqrt());
        if mid != v && mid != simple {
            out.push(mid);
        }
    }
    out
}

/// Shrinking steps of an integer toward `simple`: it, then the midpoint.
pub fn toward_int(v: u32, simple: u32) -> Vec<u32> {
    let mut out = Vec::new();
    if v != simple {
        out.push(simple);
        let mid = (v + simple) / 2;
        if mid != v && mid != simple {
            out.push(mid);
        }
    }
    out
}

/// The opening of every repro: imports, the plane, a part helper that applies properties
/// in order, the step length.
pub fn luau_prelude(title: &str, case: &str, plane: &str, tick_rate: f32) -> String {
    format!(
        r#"-- physics-bench envelope repro: {title}
-- case: {case}
-- run: physics-lua THIS_FILE
local PhysicsService = import("PhysicsService")
local Renderable = import("Renderable")
local Vector = import("Primitives").Vector
local CFrame = import("Primitives").CFrame

local world = PhysicsService.New({{ TickRate = 0, {plane} }})
local DT = 1 / {tick_rate}
local failed = false
local function check(what: string, figure: number, bound: number, atLeast: boolean?)
	local bad = figure ~= figure or (if atLeast then figure < bound else figure > bound)
	print(string.format("%s: %.6g (%s %.6g) %s", what, figure, if atLeast then ">=" else "<=", bound, if bad then "FAIL" else "ok"))
	failed = failed or bad
end
local function add(part: any, cf: any, props: {{ {{ any }} }}): any
	part.CFrame = cf
	local o: any = world:Add(part)
	for _, kv in props do
		o[kv[1]] = kv[2]
	end
	return o
end
local function basic(shape: string, size: any, cf: any, props: {{ {{ any }} }}): any
	local p = Renderable.BasePart(shape)
	p.Size = size
	return add(p, cf, props)
end
local function finite(o: any): boolean
	local p, v = o.CFrame.Position, o.Velocity
	return p.X == p.X and p.Y == p.Y and p.Z == p.Z and v.X == v.X and v.Y == v.Y and v.Z == v.Z
		and math.abs(p.X) < math.huge and math.abs(p.Y) < math.huge and math.abs(p.Z) < math.huge
end
"#
    )
}

/// The closing of every repro: fail the script when a check failed.
pub const LUAU_END: &str = r#"if failed then
	error("envelope repro: an oracle failed (see above)")
end
print("envelope repro: every oracle holds")
"#;

/// A Luau `Vector.new(...)`.
pub fn lv(v: [f64; 3]) -> String {
    format!("Vector.new({}, {}, {})", v[0], v[1], v[2])
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
