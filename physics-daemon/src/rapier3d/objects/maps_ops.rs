//! Map ops of the plane: uploading pieces, building the map object, reading it back (see
//! `maps`).

use rapier3d::prelude::*;
use shm_layout::map_op::{MapInfo, MapOp, MapReport, MAX_MAP_TRIANGLES};
use shm_layout::{CommandError, CommandResult, ErrorKind, Handle, Pose, Reply, Vec3};

use crate::rapier3d::objects::maps::{clean, PendingMap};
use crate::rapier3d::objects::object::{rapier_pose, Object, MAX_SLOTS};
use crate::rapier3d::objects::part::Part;
use crate::rapier3d::plane::Plane;

impl Plane {
    /// Routes one map op.
    pub(in crate::rapier3d) fn map_op(&mut self, op: MapOp) -> CommandResult {
        match op.checked()? {
            MapOp::Upload {
                vertices,
                triangles,
            } => {
                let total = self.objects.pending_map().triangles.len() + triangles.len();
                if total > MAX_MAP_TRIANGLES {
                    return Err(CommandError::invalid_field(
                        "Map.triangles",
                        format!("a map holds at most {MAX_MAP_TRIANGLES} triangles, this upload makes {total}"),
                    ));
                }
                let pending = self.objects.pending_map_mut();
                let base = pending.vertices.len() as u32;
                pending.vertices.extend_from_slice(&vertices);
                pending
                    .triangles
                    .extend(triangles.iter().map(|t| t.map(|i| i + base)));
                Ok(Reply::Done)
            }
            MapOp::Discard => {
                self.objects.take_pending_map();
                Ok(Reply::Done)
            }
            MapOp::Build {
                pose,
                scale,
                vertices,
                triangles,
            } => {
                let pending = self.objects.take_pending_map();
                let got = (
                    pending.vertices.len() as u64,
                    pending.triangles.len() as u64,
                );
                if got != (vertices, triangles) {
                    return Err(CommandError::invalid_field(
                        "Map",
                        format!(
                            "the map upload is incomplete: {} of {vertices} vertices and {} of \
                             {triangles} triangles arrived (a piece was refused); nothing was built",
                            got.0, got.1
                        ),
                    ));
                }
                let (handle, report) = self.build_map(&pending, pose, scale)?;
                Ok(Reply::Map(Box::new(MapInfo { handle, report })))
            }
        }
    }

    fn build_map(
        &mut self,
        pending: &PendingMap,
        pose: Pose,
        scale: Vec3,
    ) -> Result<(Handle, MapReport), CommandError> {
        if pending.triangles.is_empty() {
            return Err(CommandError::invalid_field(
                "Map.triangles",
                "the map has no triangles (upload its pieces before Build)",
            ));
        }
        let cleaned = clean(&pending.vertices, &pending.triangles, scale);
        if cleaned.triangles.is_empty() {
            return Err(CommandError::invalid_field(
                "Map.triangles",
                format!(
                    "all {} triangles of the map are degenerate (zero area)",
                    cleaned.report.triangles_in
                ),
            ));
        }
        let report = cleaned.report.clone();
        let (lo, hi) = cleaned.vertices.iter().fold(
            (Vector::splat(f32::MAX), Vector::splat(f32::MIN)),
            |(lo, hi), v| (lo.min(*v), hi.max(*v)),
        );
        let shape = SharedShape::trimesh_with_flags(
            cleaned.vertices,
            cleaned.triangles,
            TriMeshFlags::FIX_INTERNAL_EDGES,
        )
        .map_err(|e| {
            CommandError::invalid_field(
                "Map",
                format!("the map's triangle mesh cannot be built: {e}"),
            )
        })?;
        let extent = (hi - lo).max(Vector::splat(shm_layout::validate::MIN_SIZE));
        let size = extent
            .min(Vector::splat(shm_layout::validate::MAX_SIZE))
            .into();
        // One copy of each mesh in the daemon: a map another plane built (or a restore
        // brought) is shared.
        let (shape, hash, shared) = crate::rapier3d::objects::map_store::share(shape);
        let report = MapReport {
            content_hash: hash,
            shared,
            ..report
        };
        let part = Part::map(shape, hash, size, pending.cost());
        let mut collider = ColliderBuilder::new(part.collider_shape()?).build();
        part.configure_collider(&mut collider, self.queries.groups())?;
        let slot = self.objects.next_slot().ok_or_else(|| {
            CommandError::new(
                ErrorKind::Internal,
                format!("plane {} is full ({} objects)", self.id, MAX_SLOTS),
            )
        })?;
        let body = RigidBodyBuilder::fixed()
            .pose(rapier_pose(pose))
            .user_data(slot as u128)
            .build();
        let h = self.world.insert_body(body);
        self.world.insert_collider(collider, Some(h));
        self.objects
            .tally
            .add(part.hit_box_quality, part.mesh_vertex_count() as u64);
        let handle = self.objects.insert(Object {
            handle: h,
            part: Box::new(part),
            flags: 0,
        })?;
        self.queries.mark_stale(h);
        Ok((handle, report))
    }
}
