//! Scene queries (rays, sweeps, overlaps with valid or wild filters) and explosions.

use shm_layout::{FilterType, PlaneId, QueryFilter, QueryOp, Ray, Shape};

use super::Gen;

impl Gen<'_> {
    /// Any scene query, with valid or wild rays, shapes, filters and groups.
    pub(super) fn query(&mut self, wild: bool, id: PlaneId) -> QueryOp {
        let filter = QueryFilter {
            filter_type: if self.rng.chance(0.5) {
                FilterType::Exclude
            } else {
                FilterType::Include
            },
            list: (0..self.rng.below(4))
                .map(|_| self.handle(wild, id))
                .collect(),
            collision_group: self
                .rng
                .chance(0.3)
                .then(|| self.rng.below(if wild { 256 } else { 3 }) as u8),
            respect_can_collide: self.rng.chance(0.5),
        };
        let r = &mut *self.rng;
        let radius = {
            let v = r.log_f32(0.01, 5.0);
            r.maybe_wild(wild, v)
        };
        match r.below(11) {
            0 => QueryOp::Raycast {
                rays: (0..r.below(70))
                    .map(|_| Ray {
                        origin: r.vec3(wild, 30.0),
                        direction: r.vec3(wild, 60.0),
                    })
                    .collect(),
                filter,
            },
            1 => QueryOp::Spherecast {
                origin: r.vec3(wild, 30.0),
                radius,
                direction: r.vec3(wild, 60.0),
                filter,
            },
            2 => QueryOp::Blockcast {
                pose: r.pose(wild, 30.0),
                size: [radius, 1.0, 2.0],
                direction: r.vec3(wild, 60.0),
                filter,
            },
            3 => QueryOp::Shapecast {
                object: self.handle(wild, id),
                direction: self.rng.vec3(wild, 60.0),
                filter,
            },
            4 => QueryOp::BoundsInRadius {
                position: r.vec3(wild, 30.0),
                radius,
                filter,
            },
            5 => QueryOp::BoundsInBox {
                pose: r.pose(wild, 30.0),
                size: [radius, 2.0, 1.0],
                filter,
            },
            6 => QueryOp::InPart {
                object: self.handle(wild, id),
                filter,
            },
            7 => QueryOp::ProbeGround {
                position: r.vec3(wild, 30.0),
                radius,
                max_distance: r.maybe_wild(wild, 20.0),
                max_slope: r.maybe_wild(wild, 45.0),
                filter,
            },
            8 => QueryOp::ClosestPoint {
                position: r.vec3(wild, 30.0),
                max_distance: r.maybe_wild(wild, 50.0),
                filter,
            },
            9 => QueryOp::Clearance {
                shape: Shape::Capsule {
                    size: [radius, radius * 3.0, radius],
                },
                pose: r.pose(wild, 30.0),
                max_distance: r.maybe_wild(wild, 50.0),
                own: None,
                filter,
            },
            _ => QueryOp::ProbeWall {
                pose: r.pose(wild, 30.0),
                radius,
                height: r.maybe_wild(wild, 3.0),
                max_distance: r.maybe_wild(wild, 1.0),
                max_slope: r.maybe_wild(wild, 45.0),
                filter,
            },
        }
    }

    /// An explosion with valid or wild numbers and filter.
    pub(super) fn explosion(&mut self, wild: bool, id: PlaneId) -> shm_layout::Explosion {
        let filter = QueryFilter {
            list: (0..self.rng.below(3))
                .map(|_| self.handle(wild, id))
                .collect(),
            ..QueryFilter::default()
        };
        let r = &mut *self.rng;
        shm_layout::Explosion {
            center: r.vec3(wild, 30.0),
            radius: r.maybe_wild(wild, 8.0),
            impulse: r.maybe_wild(wild, 20.0),
            falloff: *r.pick(&[
                shm_layout::Falloff::Linear,
                shm_layout::Falloff::None,
                shm_layout::Falloff::InverseSquare,
            ]),
            filter,
        }
    }
}
