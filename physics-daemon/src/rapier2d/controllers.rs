//! `GUIController`: a body driven toward `MoveDirection · MoveSpeed` with at most
//! `Acceleration` px/s² per axis, jumps (`Δv = -JumpStrength / Mass` along Y, only while
//! OnGround), and waypoint paths. It steers X always and Y only when its body feels no
//! gravity (GravityScale 0 or a plane without vertical gravity): a platformer character
//! runs and jumps, a top-down or HUD NPC flies straight to its waypoints. A waypoint counts
//! as reached within WaypointRadius (measured along X alone when Y is not steered).
//!
//! OnGround is a foot probe: a 2 px strip under the body's box, as wide as the box less
//! 10 %, touching a collidable body on the same ZIndex (or a bounds wall).
//!
//! Signals are events in the plane's event stream, in this order per controller and tick:
//! `GroundChanged`, `Moved`, `WaypointReached` (one per waypoint, in path order),
//! `PathFinished`. Controllers cost nothing on a plane without any.

use rapier2d::prelude::*;
use shm_layout::gui_op::{
    GuiControllerInfo, GuiControllerOp, GuiControllerSettings, EVENT_GUI_GROUND_CHANGED,
    EVENT_GUI_MOVED, EVENT_GUI_PATH_FINISHED, EVENT_GUI_WAYPOINT_REACHED,
};
use shm_layout::{CommandError, EventRecord, Handle, Reply};

use super::controller::Controller;
use super::hooks::{on_layer, CONTROLLED};
use super::plane::Plane;
use crate::backend::counted::CountedVec;

/// Movement below this (px) in a tick is not a `Moved`.
const MOVED_EPSILON: f32 = 1e-3;

impl Plane {
    /// Applies a controller op on the body `handle`.
    pub fn controller_op(
        &mut self,
        handle: Handle,
        op: GuiControllerOp,
    ) -> Result<Reply, CommandError> {
        let op = op.checked()?;
        let h = self.body(handle)?.handle;
        let applied = Reply::Applied {
            tick: self.clock.tick,
        };
        if let GuiControllerOp::Create {
            uncontrolled,
            props,
        } = op
        {
            if self.body(handle)?.controller.is_some() {
                return Err(CommandError::invalid(format!(
                    "object {handle} already has a controller"
                )));
            }
            let mut settings = GuiControllerSettings::default();
            for p in props {
                settings.apply(p)?;
            }
            let p = self.world.bodies[h].translation();
            let on_ground = self.probe_ground(handle);
            self.bodies.get_mut(handle).expect("checked").controller = Some(Box::new(Controller {
                settings,
                uncontrolled,
                move_direction: [0.0; 2],
                jump: false,
                waypoints: CountedVec::new(&self.state_bytes),
                next: 0,
                on_ground,
                last_position: [p.x, p.y],
            }));
            self.set_object(handle, shm_layout::GuiObjectProp::LockedRotation(true))?;
            let c = self.body(handle)?.collider;
            let co = &mut self.world.colliders[c];
            co.user_data |= CONTROLLED;
            co.set_active_hooks(co.active_hooks() | ActiveHooks::MODIFY_SOLVER_CONTACTS);
            self.controlled.push(handle.slot);
            return Ok(applied);
        }
        let no_controller = || CommandError::invalid(format!("object {handle} has no controller"));
        if let GuiControllerOp::Destroy = op {
            self.body(handle)?
                .controller
                .as_ref()
                .ok_or_else(no_controller)?;
            self.destroy_object(handle)?;
            return Ok(applied);
        }
        if let GuiControllerOp::Info = op {
            let c = self
                .body(handle)?
                .controller
                .as_ref()
                .ok_or_else(no_controller)?;
            return Ok(Reply::Gui(shm_layout::GuiReply::Controller(Box::new(
                GuiControllerInfo {
                    handle,
                    settings: c.settings,
                    uncontrolled: c.uncontrolled,
                    move_direction: c.move_direction,
                    on_ground: c.on_ground,
                    waypoints: c.waypoints.to_vec(),
                    next_waypoint: c.next as u32,
                },
            ))));
        }
        let c = self
            .bodies
            .get_mut(handle)
            .expect("checked")
            .controller
            .as_deref_mut()
            .ok_or_else(no_controller)?;
        match op {
            GuiControllerOp::Set(p) => {
                c.settings.apply(p)?;
            }
            GuiControllerOp::Move(d) => c.move_direction = d,
            GuiControllerOp::Jump => c.jump = true,
            GuiControllerOp::SetWaypoints(points) => {
                c.waypoints.replace(points);
                c.next = 0;
            }
            GuiControllerOp::ClearWaypoints => {
                c.waypoints.clear();
                c.next = 0;
            }
            _ => {}
        }
        self.world.bodies[h].wake_up(true);
        Ok(applied)
    }

    /// Whether the body's Y velocity is steered (it feels no vertical gravity).
    fn steers_y(&self, rb: &RigidBody) -> bool {
        rb.gravity_scale() * self.world.gravity.y == 0.0
    }

    /// Before the step: drive every controller's body.
    pub(super) fn drive_controllers(&mut self, dt: f32) {
        if self.controlled.is_empty() {
            return;
        }
        self.refresh_scene();
        for i in 0..self.controlled.len() {
            let slot = self.controlled[i] as usize;
            let Some(handle) = self.bodies.handle_at(slot) else {
                continue;
            };
            let on_ground = self.probe_ground(handle);
            let b = self.bodies.at_mut(slot).expect("live slot");
            let h = b.handle;
            let Some(c) = b.controller.as_deref_mut() else {
                continue;
            };
            c.on_ground = on_ground;
            let jump = std::mem::take(&mut c.jump) && on_ground;
            let c = c.clone();
            let rb = &self.world.bodies[h];
            if !rb.is_dynamic() {
                continue;
            }
            let steer_y = self.steers_y(rb);
            let p = rb.translation();
            let (dir, limit) = match c.waypoints.get(c.next) {
                Some(w) => {
                    let d = Vector::new(w[0] - p.x, if steer_y { w[1] - p.y } else { 0.0 });
                    let dist = d.length();
                    if dist > 0.0 {
                        (d / dist, (dist / dt).min(c.settings.move_speed))
                    } else {
                        (Vector::ZERO, 0.0)
                    }
                }
                None => (
                    Vector::new(
                        c.move_direction[0].clamp(-1.0, 1.0),
                        if steer_y {
                            c.move_direction[1].clamp(-1.0, 1.0)
                        } else {
                            0.0
                        },
                    ),
                    c.settings.move_speed,
                ),
            };
            let target = dir * limit;
            let max_dv = c.settings.acceleration * dt;
            let v = rb.linvel();
            let approach = |v: f32, t: f32| v + (t - v).clamp(-max_dv, max_dv);
            let mut nv = Vector::new(approach(v.x, target.x), v.y);
            if steer_y {
                nv.y = approach(v.y, target.y);
            }
            if jump {
                nv.y -= c.settings.jump_strength / rb.mass();
            }
            if nv != v {
                self.world.bodies[h].set_linvel(nv, true);
            }
        }
    }

    /// After the step: the signal events of every controller, in creation order.
    pub(super) fn after_step_controllers(&mut self) {
        if self.controlled.is_empty() {
            return;
        }
        for i in 0..self.controlled.len() {
            let slot = self.controlled[i] as usize;
            let Some(handle) = self.bodies.handle_at(slot) else {
                continue;
            };
            let on_ground = self.probe_ground(handle);
            let b = self.bodies.at(slot).expect("live slot");
            let rb = &self.world.bodies[b.handle];
            let steer_y = self.steers_y(rb);
            let p = rb.translation();
            let p = [p.x, p.y];
            let record = |kind: u32, b_slot: u32, position: [f32; 3]| EventRecord {
                kind,
                a_slot: handle.slot,
                a_generation: handle.generation,
                b_slot,
                position,
                ..EventRecord::default()
            };
            let mut out = Vec::new();
            let c = self
                .bodies
                .at_mut(slot)
                .and_then(|b| b.controller.as_deref_mut())
                .expect("controlled slot");
            if on_ground != c.on_ground {
                c.on_ground = on_ground;
                out.push(record(EVENT_GUI_GROUND_CHANGED, on_ground as u32, [0.0; 3]));
            }
            let (dx, dy) = (p[0] - c.last_position[0], p[1] - c.last_position[1]);
            c.last_position = p;
            if dx.abs() > MOVED_EPSILON || dy.abs() > MOVED_EPSILON {
                out.push(record(EVENT_GUI_MOVED, 0, [dx, dy, 0.0]));
            }
            while let Some(w) = c.waypoints.get(c.next) {
                let dist = if steer_y {
                    (w[0] - p[0]).hypot(w[1] - p[1])
                } else {
                    (w[0] - p[0]).abs()
                };
                if dist > c.settings.waypoint_radius {
                    break;
                }
                c.next += 1;
                out.push(record(
                    EVENT_GUI_WAYPOINT_REACHED,
                    c.next as u32,
                    [w[0], w[1], 0.0],
                ));
                if c.next == c.waypoints.len() {
                    out.push(record(EVENT_GUI_PATH_FINISHED, 0, [0.0; 3]));
                }
            }
            for r in out {
                self.push_event(r);
            }
        }
    }

    /// OnGround: the foot strip under the body touches a collidable body of its layer.
    fn probe_ground(&self, handle: Handle) -> bool {
        let Ok(b) = self.body(handle) else {
            return false;
        };
        let Some(co) = self.world.colliders.get(b.collider) else {
            return false;
        };
        let aabb = co.compute_aabb();
        let half_w = (aabb.maxs.x - aabb.mins.x) * 0.45;
        let probe = Cuboid::new(Vector::new(half_w.max(0.01), 1.0));
        let at = Pose::from_translation(Vector::new(
            (aabb.mins.x + aabb.maxs.x) * 0.5,
            aabb.maxs.y + 1.0,
        ));
        let z = b.settings.z_index;
        let same_layer = |_: ColliderHandle, c: &Collider| on_layer(c, z);
        let filter = QueryFilter::new()
            .groups(InteractionGroups::all())
            .exclude_rigid_body(b.handle)
            .predicate(&same_layer);
        let query = self.world.query_pipeline_with_filter(filter);
        let hit = query.intersect_shape(at, &probe).next().is_some();
        hit
    }
}
