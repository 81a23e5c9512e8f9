//! Scene builders shared by `physics-bench` and the integration tests: floors, columns of
//! boxes, pyramids, piles and launched bodies, each written once so that a benchmark and a
//! test of the same scene build exactly the same world.
//!
//! Every builder adds objects through [`SceneTarget`], which both the daemon's own plane code
//! stepped in process ([`LocalPlane`]) and a daemon plane reached through client-sdk
//! (`&`[`client_sdk::Plane`]) implement; [`Spawn`] lists record a scene without a plane. A
//! builder adds its objects in a fixed order with the properties it is given applied in the
//! order given, so the same call gives the same world on every target.
//!
//! - [`target`]: the trait and its implementations.
//! - [`builders`]: the builders.
//! - [`card_house`](mod@card_house): Box2D's card house.
//! - [`peers`]: the scenes other engines publish benchmark figures for (Jolt's Pyramid,
//!   Box2D's large pyramid).
//!
//! The fuzzer of the daemon's request decoder lives in its own crate, `physics-fuzz`.

#![deny(missing_docs)]

pub mod builders;
pub mod card_house;
pub mod peers;
pub mod target;

pub use builders::*;
pub use card_house::{card_house, Card, CARD_HOUSE_SETTLE};
pub use peers::{
    jolt_pyramid, jolt_pyramid_layout, large_pyramid_gui, large_pyramid_layout, Placed,
};
pub use target::{LocalPlane, SceneTarget, Spawn};
