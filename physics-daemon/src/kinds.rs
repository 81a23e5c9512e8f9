//! The registry of plane kinds: the one place that names every implementation of
//! [`Backend`]. It sits above the seam (`backend/`) and the engines (`rapier3d/`,
//! `rapier2d/`), so neither imports the other's side.

use shm_layout::{CommandError, PlaneId, PlaneKind, PlaneProp};

use crate::backend::Backend;

/// The 3D plane kind as this daemon builds it: with the GPU path (`DeferGpu`) when built
/// with the `gpu` feature, the rapier3d plane alone without it.
#[cfg(feature = "gpu")]
pub type Plane3d = crate::gpu::GpuPlane;
/// The 3D plane kind as this daemon builds it: with the GPU path (`DeferGpu`) when built
/// with the `gpu` feature, the rapier3d plane alone without it.
#[cfg(not(feature = "gpu"))]
pub type Plane3d = crate::rapier3d::Plane;

/// Creates a plane of `kind` with its defaults, then `props` applied in order.
pub fn create(
    kind: PlaneKind,
    id: PlaneId,
    props: &[PlaneProp],
) -> Result<Box<dyn Backend>, CommandError> {
    Ok(match kind {
        PlaneKind::Rapier3d => Box::new(Plane3d::new(id, props)?),
        #[cfg(feature = "gui")]
        PlaneKind::Gui2d => Box::new(crate::rapier2d::Plane::new(id, props)?),
        #[cfg(not(feature = "gui"))]
        PlaneKind::Gui2d => {
            return Err(CommandError::invalid(
                "this daemon was built without GUI planes (cargo feature \"gui\")",
            ))
        }
    })
}
