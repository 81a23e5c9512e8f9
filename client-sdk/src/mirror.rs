//! The property mirror: what this process knows of a plane's options and its objects'
//! properties, so reading one is a local lookup instead of a round trip.
//!
//! Filled by the plane's creation reply and by one `Info` read per object; kept current by
//! this process's own writes. Only planes this process created and did not share are
//! mirrored: nobody else changes them, so the mirror can only go stale where the daemon
//! itself derives a value. Those writes drop the entry instead (Size, Weight, Density,
//! HitBoxQuality and CenterOfMass change Mass and the rotation lock; SolverIterations and
//! LoopSolver the effective iterations), as do writes the daemon rejected,
//! RecalculateCenterOfMass and Destroy: the next read asks the daemon once. Values that
//! change every tick (Sleeping, Anchored, the pose) are read from the published sample.

use std::collections::HashMap;

use shm_layout::{Handle, ObjectInfo, ObjectProp, PlaneInfo, PlaneProp};

/// One plane's mirror.
#[derive(Debug, Default)]
pub(crate) struct Mirror {
    /// This process is the plane's only writer (it created the plane, not shared).
    exclusive: bool,
    plane: Option<PlaneInfo>,
    objects: HashMap<Handle, ObjectInfo>,
}

impl Mirror {
    /// A mirror for a plane this process created: `info` is the creation reply.
    pub fn exclusive(info: PlaneInfo, shared: bool) -> Mirror {
        Mirror {
            exclusive: !shared,
            plane: (!shared).then_some(info),
            objects: HashMap::new(),
        }
    }

    /// The plane's options, when mirrored.
    pub fn plane(&self) -> Option<&PlaneInfo> {
        self.plane.as_ref()
    }

    /// Remembers the plane's options as the daemon reported them.
    pub fn store_plane(&mut self, info: &PlaneInfo) {
        if self.exclusive {
            self.plane = Some(info.clone());
        }
    }

    /// Records a plane option this process wrote.
    pub fn plane_written(&mut self, prop: &PlaneProp) {
        let derived = prop.row().derived;
        match &mut self.plane {
            Some(info) if !derived => {
                if info.settings.apply(*prop, false).is_err() {
                    self.plane = None;
                }
            }
            _ => self.plane = None,
        }
    }

    /// Forgets everything mirrored (the plane was restored from a snapshot).
    pub fn forget_all(&mut self) {
        self.plane = None;
        self.objects.clear();
    }

    /// Forgets the plane's options (a write was rejected, say).
    pub fn forget_plane(&mut self) {
        self.plane = None;
    }

    /// An object's properties, when mirrored.
    pub fn object(&self, handle: Handle) -> Option<&ObjectInfo> {
        self.objects.get(&handle)
    }

    /// Remembers an object's properties as the daemon reported them.
    pub fn store_object(&mut self, info: &ObjectInfo) {
        if self.exclusive {
            self.objects.insert(info.handle, info.clone());
        }
    }

    /// Records an object property this process wrote.
    pub fn object_written(&mut self, handle: Handle, prop: &ObjectProp) {
        // Rows flagged `derived`: the daemon recomputes mass, density or the like from them.
        let derived = prop.row().derived;
        if derived {
            self.objects.remove(&handle);
        } else if let Some(info) = self.objects.get_mut(&handle) {
            info.settings.store(prop);
        }
    }

    /// Forgets an object (destroyed, a write rejected, a value the daemon recomputed).
    pub fn forget_object(&mut self, handle: Handle) {
        self.objects.remove(&handle);
    }
}
