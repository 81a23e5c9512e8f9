//! `Raycast` on a GUI plane, and the refresh that lets queries see bodies an op added or
//! moved since the last step (their colliders' poses and broad-phase boxes).

use rapier2d::prelude::*;
use shm_layout::gui_op::{check_ray, GuiHit};
use shm_layout::settings::Vec2;
use shm_layout::CommandError;

use super::object::WALLS_SLOT;
use super::plane::Plane;
use crate::backend::rapier_world::RapierWorld;

impl Plane {
    /// Brings the colliders of bodies changed since the last step up to date for queries.
    pub(super) fn refresh_scene(&mut self) {
        self.world.refresh_colliders(&mut self.query_stale);
    }

    /// The first collidable body (any ZIndex; walls excluded) the ray meets.
    pub fn raycast(
        &mut self,
        from: Vec2,
        dir: Vec2,
        max_distance: Option<f32>,
    ) -> Result<Option<GuiHit>, CommandError> {
        let unit = check_ray(from, dir, max_distance)?;
        self.refresh_scene();
        let ray = Ray::new(Vector::from(from), Vector::from(unit));
        let bodies = &self.world.bodies;
        let not_wall = |_: ColliderHandle, c: &Collider| {
            c.parent()
                .and_then(|b| bodies.get(b))
                .is_some_and(|b| b.user_data as usize != WALLS_SLOT)
        };
        let filter = QueryFilter::new()
            .groups(InteractionGroups::all())
            .predicate(&not_wall);
        let query = self.world.query_pipeline_with_filter(filter);
        let reach = max_distance.unwrap_or(f32::MAX);
        let Some((c, hit)) = query.cast_ray_and_get_normal(&ray, reach, true) else {
            return Ok(None);
        };
        let Some(slot) = self
            .world
            .colliders
            .get(c)
            .and_then(|co| co.parent())
            .and_then(|b| self.world.bodies.get(b))
            .map(|b| b.user_data as usize)
        else {
            return Ok(None);
        };
        let Some(handle) = self.bodies.handle_at(slot) else {
            return Ok(None);
        };
        let p = ray.point_at(hit.time_of_impact);
        Ok(Some(GuiHit {
            handle,
            distance: hit.time_of_impact,
            position: [p.x, p.y],
            normal: [hit.normal.x, hit.normal.y],
        }))
    }
}
