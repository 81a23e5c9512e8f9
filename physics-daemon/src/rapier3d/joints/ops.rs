//! Joint ops of the plane: create, set, info, list, destroy, and the joints of a removed body.

use rapier3d::prelude::*;
use shm_layout::joint_op::{JointInfo, JointKind, JointOp, JointProp, JointSettings};
use shm_layout::{CommandError, CommandResult, Handle, Reply};

use crate::rapier3d::joints::articulations;
use crate::rapier3d::joints::build::build;
use crate::rapier3d::joints::table::Joint;
use crate::rapier3d::plane::Plane;

impl Plane {
    /// The articulated ball joints with limits: (link, twist limit, swing limit), a missing
    /// limit as π.
    pub(in crate::rapier3d) fn limited_ball_links(&self) -> Vec<(MultibodyJointHandle, f32, f32)> {
        (0..self.joints.table.slot_count())
            .filter_map(|i| {
                let j = self.joints.table.at(i)?;
                let link = j.link?;
                articulations::needs_limit_joint(j.kind, &j.settings).then(|| {
                    let pi = std::f32::consts::PI;
                    (
                        link,
                        j.settings.twist_limit.unwrap_or(pi),
                        j.settings.swing_limit.unwrap_or(pi),
                    )
                })
            })
            .collect()
    }

    /// The force each articulated joint carried over the last step, keyed by its child body
    /// (what `articulations::set_armature` sizes a joint's armature for).
    pub(in crate::rapier3d) fn articulated_loads(
        &self,
    ) -> std::collections::HashMap<RigidBodyHandle, f32> {
        (0..self.joints.table.slot_count())
            .filter_map(|i| {
                let j = self.joints.table.at(i)?;
                let link = j.link?;
                let child = if link.0 == j.body_a.0 {
                    j.body_a
                } else {
                    j.body_b
                };
                Some((child, j.force))
            })
            .collect()
    }

    /// Forgets every joint's articulation (the trees were torn down): companions go, and
    /// each joint is looked at again before the next step.
    pub(in crate::rapier3d) fn forget_articulated(&mut self) {
        for i in 0..self.joints.table.slot_count() {
            let Some(j) = self.joints.table.at_mut(i) else {
                continue;
            };
            if j.link.is_none() && j.limit.is_none() {
                continue;
            }
            j.link = None;
            j.seen = None;
            if let Some(l) = j.limit.take() {
                self.world.impulse_joints.remove(l, true);
            }
        }
    }
}

impl Plane {
    /// Routes one joint op.
    pub(in crate::rapier3d) fn joint_op(&mut self, op: JointOp) -> CommandResult {
        match op.checked()? {
            JointOp::Create { kind, a, b, props } => {
                let handle = self.create_joint(kind, a, b, &props)?;
                Ok(Reply::Joint {
                    handle,
                    tick: self.clock.tick,
                })
            }
            JointOp::Set { joint, prop } => {
                self.set_joint(joint, prop)?;
                Ok(Reply::Applied {
                    tick: self.clock.tick,
                })
            }
            JointOp::Info { joint } => Ok(Reply::JointInfo(Box::new(self.joint_info(joint)?))),
            JointOp::List { after, limit } => Ok(Reply::Joints(self.joint_page(after, limit))),
            JointOp::Destroy { joint } => {
                let j = self.joints.table.remove(joint)?;
                self.remove_rapier_joint(&j);
                self.joint_holds(j.a, -1);
                if let Some(b) = j.b {
                    self.joint_holds(b, -1);
                }
                Ok(Reply::Applied {
                    tick: self.clock.tick,
                })
            }
        }
    }

    pub(in crate::rapier3d::joints) fn ground(&mut self) -> RigidBodyHandle {
        if let Some(g) = self.joints.ground {
            return g;
        }
        let g = self
            .world
            .insert_body(RigidBodyBuilder::fixed().user_data(u128::MAX).build());
        self.joints.ground = Some(g);
        g
    }

    pub(in crate::rapier3d::joints) fn create_joint(
        &mut self,
        kind: JointKind,
        a: Handle,
        b: Option<Handle>,
        props: &[JointProp],
    ) -> Result<Handle, CommandError> {
        let body_a = self.body_of(a)?;
        let body_b = match b {
            Some(b) if b == a => {
                return Err(CommandError::invalid_field(
                    "objB",
                    "a joint needs two different objects (objB is objA)",
                ))
            }
            Some(b) => self.body_of(b)?,
            None => self.ground(),
        };
        let mut settings = JointSettings::default();
        for p in props {
            settings.store(*p);
        }
        settings.check(kind)?;
        let rel =
            self.world.bodies[body_b].rotation().inverse() * *self.world.bodies[body_a].rotation();
        let data = build(kind, &settings, rel);
        let rapier = self.world.insert_impulse_joint(body_a, body_b, data);
        let joint = Joint {
            kind,
            a,
            b,
            body_a,
            body_b,
            rel,
            rapier: Some(rapier),
            settings,
            error: 0.0,
            angular_error: 0.0,
            force: 0.0,
            position: 0.0,
            broken: false,
            seen: None,
            dirty: false,
            link: None,
            limit: None,
        };
        self.joints.articulations.dirty = true;
        match self.joints.table.insert(joint) {
            Ok(h) => {
                self.joint_holds(a, 1);
                if let Some(b) = b {
                    self.joint_holds(b, 1);
                }
                self.measure_joint(h);
                Ok(h)
            }
            Err(e) => {
                self.world.remove_impulse_joint(rapier);
                Err(e)
            }
        }
    }

    pub(in crate::rapier3d::joints) fn set_joint(
        &mut self,
        handle: Handle,
        prop: JointProp,
    ) -> Result<(), CommandError> {
        let joint = self.joints.table.get(handle)?;
        let mut settings = joint.settings;
        settings.store(prop);
        settings.check(joint.kind)?;
        let structural = articulations::articulable(joint.kind, &joint.settings)
            != articulations::articulable(joint.kind, &settings)
            || articulations::needs_limit_joint(joint.kind, &joint.settings)
                != articulations::needs_limit_joint(joint.kind, &settings);
        let j = self.joints.table.get_mut(handle)?;
        j.settings = settings;
        j.dirty = true;
        let ends = [Some(j.a), j.b];
        self.joints.articulations.dirty |= structural;
        // A joint write wakes both ends, as an object write does: a sleeping door at its
        // limit must feel a new motor or limit (rapier wakes a body's whole island, an
        // articulation's links with it, at the next step).
        for object in ends.into_iter().flatten() {
            self.wake(object)?;
        }
        Ok(())
    }

    pub(in crate::rapier3d::joints) fn joint_info(
        &self,
        handle: Handle,
    ) -> Result<JointInfo, CommandError> {
        let j = self.joints.table.get(handle)?;
        Ok(JointInfo {
            handle,
            kind: j.kind,
            a: j.a,
            b: j.b,
            settings: j.settings,
            error: j.error,
            angular_error: j.angular_error,
            broken: j.broken,
            force: j.force,
            position: j.position,
        })
    }

    /// The live joints from slot `after` on, ascending, at most `limit` (checked: 1 to
    /// `MAX_JOINT_PAGE`), each described as `JointOp::Info` describes it.
    pub(in crate::rapier3d::joints) fn joint_page(&self, after: u32, limit: u32) -> Vec<JointInfo> {
        let table = &self.joints.table;
        (after as usize..table.slot_count())
            .filter_map(|slot| self.joint_info(table.handle_at(slot)?).ok())
            .take(limit as usize)
            .collect()
    }

    pub(in crate::rapier3d::joints) fn remove_rapier_joint(&mut self, j: &Joint) {
        if let Some(r) = j.rapier {
            self.world.impulse_joints.remove(r, true);
        }
        if let Some(l) = j.limit {
            self.world.impulse_joints.remove(l, true);
        }
        if j.link.is_some() {
            self.tear_down_articulations();
        }
        self.joints.articulations.dirty = true;
    }

    /// Removes every joint attached to an object that is being destroyed (before its body
    /// goes).
    pub(in crate::rapier3d) fn remove_joints_of(&mut self, body: RigidBodyHandle) {
        if self.joints.table.live() == 0 {
            return;
        }
        let doomed: Vec<Handle> = (0..self.joints.table.slot_count())
            .filter_map(|i| {
                let j = self.joints.table.at(i)?;
                (j.body_a == body || j.body_b == body)
                    .then(|| self.joints.table.handle_at(i))
                    .flatten()
            })
            .collect();
        for h in doomed {
            if let Ok(j) = self.joints.table.remove(h) {
                self.remove_rapier_joint(&j);
                self.joint_holds(j.a, -1);
                if let Some(b) = j.b {
                    self.joint_holds(b, -1);
                }
            }
        }
    }

    /// Counts a joint more (`1`) or less (`-1`) holding `object`, and refreshes its body's
    /// rotation lock: a part a joint holds is free to rotate (see
    /// `Part::rotation_locked_by_quality`).
    pub(in crate::rapier3d::joints) fn joint_holds(&mut self, object: Handle, delta: i32) {
        let Ok(body) = self.objects.get_mut(object) else {
            return; // gone with its joint
        };
        let h = body.handle;
        body.part.joints = body.part.joints.saturating_add_signed(delta);
        let part = &body.part;
        if let Some(rb) = self.world.bodies.get_mut(h) {
            rb.set_locked_axes(part.locked_axes(), true);
        }
    }
}
