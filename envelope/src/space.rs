//! The parameter ranges of every family, as data (each family's file declares its ranges
//! struct; [`Space`] holds one of each): [`FULL`] is what `physics-bench
//! envelope` explores; [`HOLDS`] is the documented envelope, where every oracle holds at
//! the time of writing (tests/tests/envelope.rs asserts it). Widen a family's `HOLDS` entry
//! as fixes land; narrow it (and say so in docs/stability.md) when a change breaks it.

pub use crate::families::chain::ChainRanges;
pub use crate::families::drop::DropRanges;
pub use crate::families::pile::PileRanges;
pub use crate::families::projectile::ProjectileRanges;
pub use crate::families::spring::SpringRanges;
pub use crate::families::stack::StackRanges;
pub use crate::setting::SettingRanges;

use crate::families::chain::{Kind, Solver, StartPose};
use crate::families::drop::ALL_SHAPES;
use crate::families::projectile::Target;
use crate::families::spring::SpringKind;
use crate::families::stack::Order;
use crate::rng::Span;

/// One range set per family.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Space {
    pub stack: StackRanges,
    pub chain: ChainRanges,
    pub projectile: ProjectileRanges,
    pub drop: DropRanges,
    pub spring: SpringRanges,
    pub pile: PileRanges,
}

const WIDE: SettingRanges = SettingRanges {
    tick_rate: Span(30.0, 240.0),
    iterations: (1, 16),
    quality: (1, 32),
};

const DEFAULTS: SettingRanges = SettingRanges {
    tick_rate: Span::at(60.0),
    iterations: (4, 4),
    quality: (1, 1),
};

/// What the fuzzer explores: the ranges.
pub const FULL: Space = Space {
    stack: StackRanges {
        setting: WIDE,
        count: (2, 6),
        ratio: Span(1.0, 1e4),
        size: Span(0.05, 100.0),
        orders: &[Order::HeavyTop, Order::HeavyBottom, Order::Alternating],
    },
    chain: ChainRanges {
        setting: WIDE,
        links: (2, 30),
        ratio: Span(1.0, 1e4),
        link: Span(0.1, 10.0),
        poses: &[StartPose::Hanging, StartPose::Horizontal, StartPose::Coiled],
        kinds: &[Kind::Ball, Kind::Hinge],
        solvers: &[Solver::Articulation, Solver::Impulse],
    },
    projectile: ProjectileRanges {
        setting: WIDE,
        targets: &[Target::Wall, Target::Body],
        speed: Span(10.0, 10_000.0),
        radius: Span(0.05, 1.0),
        thickness: Span(0.01, 10.0),
        target_quality: (1, 32),
        angle: Span(0.0, 60.0),
        mass_ratio: Span(0.1, 100.0),
    },
    drop: DropRanges {
        setting: WIDE,
        shapes: &ALL_SHAPES,
        size: Span(0.05, 100.0),
        aspect: Span(0.5, 3.0),
        height: Span(0.01, 20.0),
    },
    spring: SpringRanges {
        setting: WIDE,
        kinds: &[SpringKind::Spring, SpringKind::AxisSpring],
        stiffness: Span(1.0, 1e5),
        mass: Span(0.1, 100.0),
        amplitude: Span(0.05, 1.5),
    },
    pile: PileRanges {
        setting: SettingRanges {
            tick_rate: Span(30.0, 480.0),
            ..WIDE
        },
        count: (1, 40),
        size: Span(0.05, 100.0),
        offset: Span(1.0, 1e5),
        at_origin: 0.3,
        round: &[false, true],
    },
};

/// The documented envelope: where every oracle holds today at the defaults, the ranges
/// tests/tests/envelope.rs draws from (measured with `physics-bench envelope --holds`; the
/// critical values in docs/stability.md say where each family stops holding).
pub const HOLDS: Space = Space {
    // A 2-box heavy-on-light stack holds to 100:1, a 1/R/1/R column only to 10:1 (at 30:1
    // it keeps hopping and never sleeps).
    stack: StackRanges {
        setting: DEFAULTS,
        count: (2, 4),
        ratio: Span(1.0, 10.0),
        size: Span(0.2, 10.0),
        orders: &[Order::HeavyTop, Order::HeavyBottom, Order::Alternating],
    },
    // Articulations (the default for a tree of joints) from every start pose.
    chain: ChainRanges {
        setting: DEFAULTS,
        links: (2, 20),
        ratio: Span(1.0, 1000.0),
        link: Span(0.5, 2.0),
        poses: &[StartPose::Hanging, StartPose::Horizontal, StartPose::Coiled],
        kinds: &[Kind::Ball, Kind::Hinge],
        solvers: &[Solver::Articulation],
    },
    projectile: ProjectileRanges {
        setting: DEFAULTS,
        targets: &[Target::Wall, Target::Body],
        speed: Span(10.0, 10_000.0),
        radius: Span(0.1, 1.0),
        thickness: Span(0.05, 10.0),
        target_quality: (1, 1),
        angle: Span(0.0, 45.0),
        mass_ratio: Span(0.1, 100.0),
    },
    // Every shape at the default quality (at 2-8 cubes, capsules, pyramids and wedges
    // drift or tip).
    drop: DropRanges {
        setting: DEFAULTS,
        shapes: &ALL_SHAPES,
        size: Span(0.2, 10.0),
        aspect: Span(0.5, 2.0),
        height: Span(0.01, 10.0),
    },
    // Undamped springs keep their energy only well above 1 rad/s (ω = √(k/m) ≥ 3.9 here);
    // slower ones lose 10-20 % in 10 s.
    spring: SpringRanges {
        setting: DEFAULTS,
        kinds: &[SpringKind::AxisSpring, SpringKind::Spring],
        stiffness: Span(30.0, 1000.0),
        mass: Span(0.5, 2.0),
        amplitude: Span(0.1, 1.0),
    },
    pile: PileRanges {
        setting: DEFAULTS,
        count: (1, 20),
        size: Span(0.2, 10.0),
        offset: Span(1.0, 1e3),
        at_origin: 0.5,
        round: &[false, true],
    },
};
