//! The GPU path of 3D planes (`DeferGpu = true`): a wgpu compute world that steps spheres and
//! axis-aligned boxes with single-point contacts, a spatial-hash broadphase built on the GPU
//! every substep (so the cost grows linearly with the body count), and ping-ponging state
//! buffers read back once per tick for publishing.
//!
//! - `context`: [`Context`], the wgpu device and compiled pipelines, created once per daemon
//!   the first time a plane asks for the GPU (no wgpu instance exists before) and shared by
//!   planes.
//! - `world`: [`GpuWorld`], one plane's buffers, uploads, the step and the readback.
//! - `broadphase`: the hash grid's sizing, the prefix-sum levels and the pair modes.
//! - `plane`: [`GpuPlane`], the 3D plane kind of a daemon with the GPU path: a wrapper
//!   around the rapier3d plane behind the backend seam that owns a `GpuWorld` while
//!   `DeferGpu` is true and hands it every body's pose and velocity when it flips.
//!
//! `PHYSICS_GPU=off` in the daemon's environment hides every adapter (as on a machine
//! without one), so the refusal path can be exercised anywhere.

mod broadphase;
mod context;
mod plane;
mod world;

pub use broadphase::PairMode;
pub use context::{adapter_name, context, Context};
pub use plane::GpuPlane;
pub use world::{GpuBody, GpuWorld, StepEnv};
