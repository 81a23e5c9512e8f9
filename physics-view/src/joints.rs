//! The joints overlay: each joint of a plane drawn as a line from object A's anchor to
//! object B's (or to the world point of a joint to the world). The plane's joints are
//! listed (`Plane::joints`, a read any client may make) at most once a second for a live
//! plane and once per displayed tick for the replay plane; the anchors, local to each
//! object, are placed with the poses of the tick drawn.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use client_sdk::{Error, JointInfo, Plane, Vec3};
use serde_json::{json, Value};
use shm_layout::geometry::rotate;

/// A live plane's joints are listed again after this long (joints come and go far less
/// often than bodies move; their anchors follow the bodies at every tick regardless).
pub const JOINT_REFRESH: Duration = Duration::from_secs(1);
/// Most joints drawn (a plane may hold a million; the page draws this many lines at most).
pub const MAX_JOINTS_DRAWN: usize = 16_384;

/// A body's pose at the tick drawn: generation, position, rotation `[x, y, z, w]`.
pub type PoseOf = (u32, Vec3, [f32; 4]);

/// The joints of one plane as last listed.
#[derive(Default)]
pub struct JointCache {
    /// When they were listed and at which tick (`None`: never).
    listed: Option<(Instant, u64)>,
    joints: Vec<JointInfo>,
}

impl JointCache {
    /// Lists the plane's joints again when due: for the replay plane (`per_tick`) when the
    /// tick drawn is not the one listed, otherwise when [`JOINT_REFRESH`] has passed. A plane
    /// that refuses the list (a plane kind without joints) has none; a lost daemon is
    /// reported.
    pub fn refresh(&mut self, plane: &Plane, tick: u64, per_tick: bool) -> Result<(), Error> {
        let due = match self.listed {
            None => true,
            Some((at, listed)) if per_tick => listed != tick || at.elapsed() > JOINT_REFRESH,
            Some((at, _)) => at.elapsed() >= JOINT_REFRESH,
        };
        if !due {
            return Ok(());
        }
        self.joints = match plane.joints() {
            Ok(joints) => joints,
            Err(Error::Command(_)) => Vec::new(),
            Err(e) => return Err(e),
        };
        self.listed = Some((Instant::now(), tick));
        Ok(())
    }

    /// The joints as last listed.
    pub fn joints(&self) -> &[JointInfo] {
        &self.joints
    }
}

/// A local point of a body in the world.
fn world_point(pose: &PoseOf, local: Vec3) -> Vec3 {
    let r = rotate(pose.2, local);
    [0, 1, 2].map(|k| pose.1[k] + r[k])
}

/// The lines to draw: for each joint whose objects are live at the tick drawn (same slot
/// and generation), A's anchor in the world to B's (or to `AnchorB` itself, a world point,
/// when B is the world), at most [`MAX_JOINTS_DRAWN`]. A joint whose object is gone since
/// the list, or whose pose is not finite, is left out.
pub fn lines(joints: &[JointInfo], poses: &HashMap<u32, PoseOf>) -> Vec<Value> {
    let pose = |h: client_sdk::Handle| poses.get(&h.slot).filter(|p| p.0 == h.generation);
    let finite = |p: &Vec3| p.iter().all(|v| v.is_finite());
    let mut out = Vec::new();
    for j in joints {
        if out.len() >= MAX_JOINTS_DRAWN {
            break;
        }
        let Some(a) = pose(j.a) else { continue };
        let from = world_point(a, j.settings.anchor_a);
        let to = match j.b {
            Some(b) => match pose(b) {
                Some(b) => world_point(b, j.settings.anchor_b),
                None => continue,
            },
            None => j.settings.anchor_b,
        };
        if !(finite(&from) && finite(&to)) {
            continue;
        }
        out.push(json!({
            "slot": j.handle.slot,
            "kind": j.kind.name(),
            "a": j.a.slot,
            "b": j.b.map(|b| b.slot),
            "from": from,
            "to": to,
            "broken": j.broken,
        }));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use client_sdk::{Handle, JointKind};
    use shm_layout::joint_op::JointSettings;

    fn joint(slot: u32, a: Handle, b: Option<Handle>, anchors: (Vec3, Vec3)) -> JointInfo {
        JointInfo {
            handle: Handle {
                slot,
                generation: 1,
            },
            kind: JointKind::Ball,
            a,
            b,
            settings: JointSettings {
                anchor_a: anchors.0,
                anchor_b: anchors.1,
                ..JointSettings::default()
            },
            error: 0.0,
            angular_error: 0.0,
            broken: slot == 2,
            force: 0.0,
            position: 0.0,
        }
    }

    fn close(a: &Value, b: Vec3) -> bool {
        (0..3).all(|k| (a[k].as_f64().unwrap() - b[k] as f64).abs() < 1e-5)
    }

    #[test]
    fn anchors_are_placed_by_each_objects_pose() {
        let h = |slot, generation| Handle { slot, generation };
        // A turned a quarter about +Y (x → -z), B not turned; a world joint; a joint to a
        // body gone since the list (generation 1, now 2); one to a slot with no body.
        let half = std::f32::consts::FRAC_1_SQRT_2;
        let poses: HashMap<u32, PoseOf> = [
            (0, (1, [1.0, 2.0, 3.0], [0.0, half, 0.0, half])),
            (1, (1, [5.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0])),
            (3, (2, [0.0; 3], [0.0, 0.0, 0.0, 1.0])),
        ]
        .into_iter()
        .collect();
        let joints = [
            joint(
                0,
                h(0, 1),
                Some(h(1, 1)),
                ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            ),
            joint(2, h(1, 1), None, ([0.0, 0.0, 0.5], [7.0, 8.0, 9.0])),
            joint(4, h(0, 1), Some(h(3, 1)), ([0.0; 3], [0.0; 3])),
            joint(5, h(9, 1), None, ([0.0; 3], [0.0; 3])),
        ];
        let out = lines(&joints, &poses);
        assert_eq!(out.len(), 2, "{out:?}");
        assert_eq!(out[0]["slot"], 0);
        // (1, 0, 0) turned a quarter about +Y is (0, 0, -1).
        assert!(close(&out[0]["from"], [1.0, 2.0, 2.0]), "{}", out[0]);
        assert!(close(&out[0]["to"], [5.0, 1.0, 0.0]), "{}", out[0]);
        assert_eq!(out[0]["broken"], false);
        assert_eq!(out[1]["slot"], 2);
        assert!(close(&out[1]["from"], [5.0, 0.0, 0.5]), "{}", out[1]);
        assert!(close(&out[1]["to"], [7.0, 8.0, 9.0]), "{}", out[1]);
        assert_eq!(out[1]["b"], Value::Null);
        assert_eq!(out[1]["broken"], true);
    }

    #[test]
    fn no_more_than_the_cap_are_drawn_and_bad_poses_are_skipped() {
        let h = |slot| Handle {
            slot,
            generation: 1,
        };
        let mut poses: HashMap<u32, PoseOf> = HashMap::new();
        poses.insert(0, (1, [0.0; 3], [0.0, 0.0, 0.0, 1.0]));
        poses.insert(1, (1, [f32::NAN, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]));
        let many: Vec<JointInfo> = (0..MAX_JOINTS_DRAWN as u32 + 10)
            .map(|i| joint(i + 10, h(0), None, ([0.0; 3], [1.0, 0.0, 0.0])))
            .collect();
        assert_eq!(lines(&many, &poses).len(), MAX_JOINTS_DRAWN);
        let bad = [joint(3, h(1), Some(h(0)), ([0.0; 3], [0.0; 3]))];
        assert!(lines(&bad, &poses).is_empty());
    }
}
