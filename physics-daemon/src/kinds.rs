//! The registry of plane kinds: the one place that names every implementation of
//! [`Backend`]. It sits above the seam (`backend/`) and the engines (`rapier3d/`,
//! `rapier2d/`), so neither imports the other's side.

use shm_layout::{CommandError, PlaneId, PlaneKind, PlaneProp};

use crate::backend::Backend;

/// Creates a plane of `kind` with its defaults, then `props` applied in order.
pub fn create(
    kind: PlaneKind,
    id: PlaneId,
    props: &[PlaneProp],
) -> Result<Box<dyn Backend>, CommandError> {
    Ok(match kind {
        PlaneKind::Rapier3d => Box::new(crate::rapier3d::Plane::new(id, props)?),
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
