//! Controller ops: create, set, path, jump, teleport, info, destroy.

use super::*;
use crate::rapier3d::plane::Plane;

impl Plane {
    /// Runs one controller op.
    pub fn controller_op(&mut self, op: ControllerOp) -> Result<Reply, CommandError> {
        match op.checked()? {
            ControllerOp::Create {
                pose,
                size,
                controlled,
                props,
            } => {
                let handle = self.create_controller(pose, size, controlled, &props)?;
                Ok(Reply::Object {
                    handle,
                    tick: self.clock.tick,
                })
            }
            ControllerOp::Set { handle, prop } => {
                self.set_controller(handle, prop)?;
                Ok(Reply::Applied {
                    tick: self.clock.tick,
                })
            }
            ControllerOp::Info { handle } => {
                // The wall probe of the info reads the scene as ops left it.
                self.refresh_scene();
                Ok(Reply::Controller(Box::new(self.controller_info(handle)?)))
            }
            ControllerOp::SetPath { handle, waypoints } => {
                let c = self.controller_mut(handle)?;
                c.path
                    .replace(waypoints.into_iter().map(Vector::from).collect());
                c.path_index = 0;
                Ok(Reply::Applied {
                    tick: self.clock.tick,
                })
            }
            ControllerOp::AppendWaypoint { handle, point } => {
                let c = self.controller_mut(handle)?;
                if c.path.len() >= shm_layout::controller_op::MAX_WAYPOINTS {
                    return Err(CommandError::invalid_field(
                        "waypoint",
                        "the path already holds the most waypoints allowed",
                    ));
                }
                if c.path_index >= c.path.len() {
                    c.path.clear();
                    c.path_index = 0;
                }
                c.path.push(Vector::from(point));
                Ok(Reply::Applied {
                    tick: self.clock.tick,
                })
            }
            ControllerOp::StopWalking { handle } => {
                let c = self.controller_mut(handle)?;
                c.path.clear();
                c.path_index = 0;
                c.move_vector = [0.0; 2];
                Ok(Reply::Applied {
                    tick: self.clock.tick,
                })
            }
            ControllerOp::Jump { handle } => {
                let c = self.controller_mut(handle)?;
                let launched = c.on_ground;
                c.jump |= launched;
                Ok(Reply::Flag(launched))
            }
            ControllerOp::Teleport { handle, pose } => {
                let yaw = yaw_of(pose.rotation);
                let c = self.controller_mut(handle)?;
                c.velocity = Vector::ZERO;
                c.path.clear();
                c.path_index = 0;
                c.yaw = yaw;
                c.intent_yaw = yaw;
                c.ground = None;
                self.place_controller(handle, Vector::from(pose.position), yaw)?;
                Ok(Reply::Applied {
                    tick: self.clock.tick,
                })
            }
            ControllerOp::Destroy { handle } => {
                self.controller_mut(handle)?;
                self.destroy_object(handle)?;
                Ok(Reply::Applied {
                    tick: self.clock.tick,
                })
            }
        }
    }

    pub(in crate::rapier3d) fn create_controller(
        &mut self,
        pose: Pose,
        size: Vec3,
        controlled: bool,
        props: &[ControllerProp],
    ) -> Result<Handle, CommandError> {
        let mut settings = ControllerSettings::defaults(size, controlled);
        let yaw = yaw_of(pose.rotation);
        let mut controller = Controller::new(settings, yaw, &self.state_bytes);
        let mut state = Vec::new();
        for prop in props {
            if !settings.apply(*prop)? {
                state.push(*prop);
            }
        }
        controller.settings = settings;
        // The object's part is the capsule (mass, Density, groups, queries all see it).
        let mut part = Part::new(&Shape::Capsule {
            size: controller.size(),
        });
        part.is_controller = true;
        let mut collider = ColliderBuilder::new(controller.shape()).build();
        part.configure_collider(&mut collider, self.queries.groups())?;
        let slot = self
            .objects
            .next_slot()
            .ok_or_else(|| CommandError::invalid(format!("plane {} is full", self.id)))?;
        let body = RigidBodyBuilder::kinematic_position_based()
            .pose(rapier3d::math::Pose::from_parts(
                Vector::from(pose.position),
                yaw_rotation(yaw),
            ))
            .user_data(slot as u128)
            .build();
        let h = self.world.insert_body(body);
        self.world.insert_collider(collider, Some(h));
        self.objects.tally_mut().add(part.hit_box_quality, 0);
        let handle = self.objects.insert(Object {
            handle: h,
            part: Box::new(part),
            flags: shm_layout::FLAG_CONTROLLER,
        })?;
        self.queries.mark_stale(h);
        self.controllers.insert(handle.slot, controller);
        for prop in state {
            self.set_controller(handle, prop)?;
        }
        Ok(handle)
    }

    pub(in crate::rapier3d) fn controller_mut(
        &mut self,
        handle: Handle,
    ) -> Result<&mut Controller, CommandError> {
        self.body_of(handle)?;
        self.controllers.get_mut(&handle.slot).ok_or_else(|| {
            CommandError::invalid_field(
                "controller",
                format!("object {handle} of plane {} is not a controller", self.id),
            )
        })
    }

    /// Moves a controller's body to `position` facing `yaw` at once (a teleport).
    pub(in crate::rapier3d) fn place_controller(
        &mut self,
        handle: Handle,
        position: Vector,
        yaw: f32,
    ) -> Result<(), CommandError> {
        let h = self.changing(handle)?;
        let pose = rapier3d::math::Pose::from_parts(position, yaw_rotation(yaw));
        let body = &mut self.world.bodies[h];
        body.set_position(pose, true);
        body.set_next_kinematic_position(pose);
        self.queries.mark_stale(h);
        Ok(())
    }

    pub(in crate::rapier3d) fn set_controller(
        &mut self,
        handle: Handle,
        prop: ControllerProp,
    ) -> Result<(), CommandError> {
        let prop = prop.checked()?;
        let c = self.controller_mut(handle)?;
        let shape_before = (c.settings.capsule_radius, c.settings.capsule_half_height);
        let mut settings = c.settings;
        if settings.apply(prop)? {
            c.settings = settings;
            if shape_before != (settings.capsule_radius, settings.capsule_half_height) {
                let size = c.size();
                let shape = c.shape();
                let h = self.body_of(handle)?;
                self.objects.get_mut(handle)?.part.size = size;
                for col in self.world.bodies[h].colliders().to_vec() {
                    self.world.colliders[col].set_shape(shape.clone());
                }
                self.queries.mark_stale(h);
            }
            return Ok(());
        }
        match prop {
            ControllerProp::Position(p) => {
                let yaw = c.yaw;
                c.velocity = Vector::ZERO;
                c.ground = None;
                self.place_controller(handle, Vector::from(p), yaw)?;
            }
            ControllerProp::Velocity(v) => {
                c.velocity = Vector::from(v);
                if v[1] > 0.0 {
                    c.on_ground = false;
                }
            }
            ControllerProp::Rotation(r) => {
                c.yaw = r[1];
                c.intent_yaw = r[1];
                let yaw = c.yaw;
                let h = self.body_of(handle)?;
                let pos = self.world.bodies[h].translation();
                self.place_controller(handle, pos, yaw)?;
            }
            ControllerProp::MoveVector(m) => {
                if m != c.move_vector {
                    c.intent_yaw = c.yaw;
                }
                c.move_vector = m;
            }
            _ => {}
        }
        Ok(())
    }

    pub(in crate::rapier3d) fn controller_info(
        &self,
        handle: Handle,
    ) -> Result<ControllerInfo, CommandError> {
        self.body_of(handle)?;
        let c = self.controllers.get(&handle.slot).ok_or_else(|| {
            CommandError::invalid_field(
                "controller",
                format!("object {handle} is not a controller"),
            )
        })?;
        Ok(ControllerInfo {
            handle,
            settings: c.settings,
            velocity: c.velocity.into(),
            rotation: [0.0, c.yaw, 0.0],
            on_ground: c.on_ground,
            move_vector: c.move_vector,
            path_length: c.path.len() as u32,
            path_index: if c.path_index < c.path.len() {
                c.path_index as u32 + 1
            } else {
                0
            },
            // Probed on request, where the last tick's move left the capsule: a tick pays
            // nothing for it.
            wall_normal: self.controller_wall(handle, c).into(),
        })
    }
}
