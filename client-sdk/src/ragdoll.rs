//! Ragdolls: bones are capsule objects, each joined to its parent bone by a ConeTwist
//! joint whose twist axis is the bone's own axis (its local Y) and whose swing and twist
//! limits the description gives per bone. [`RagdollDesc::humanoid`] is the default 15-bone
//! humanoid.

use shm_layout::geometry::rotate;
use shm_layout::{JointKind, JointProp, ObjectProp, Pose, Shape, Vec3};

use crate::{error::Error, joint::Joint, object::Object, plane::Plane};

/// What every bone gets first: HitBoxQuality 2, since a capsule below 2 has its rotation
/// locked against contacts (and joints could not turn it), and CCD for hits.
pub const BONE_PROPS: [ObjectProp; 1] = [ObjectProp::HitBoxQuality(2)];

/// One bone of a ragdoll description.
#[derive(Debug, Clone, PartialEq)]
pub struct Bone {
    /// Its name (unique in the ragdoll).
    pub name: String,
    /// The bone it hangs from (listed before it); `None` for the root.
    pub parent: Option<String>,
    /// Capsule radius.
    pub radius: f32,
    /// Capsule length end to end along the bone's local Y (at least 2·radius).
    pub length: f32,
    /// Rest pose of the capsule's centre, Y along the bone.
    pub pose: Pose,
    /// World point of the joint to the parent at rest; `None`: the bone's +Y end.
    pub joint: Option<Vec3>,
    /// Swing cone half-angle (radians) away from the rest pose, in (0, π].
    pub swing_limit: f32,
    /// Twist range ±limit (radians) about the bone's axis, in (0, π].
    pub twist_limit: f32,
}

/// A ragdoll description: bones, parents before children.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RagdollDesc {
    /// The bones.
    pub bones: Vec<Bone>,
}

/// A ragdoll in a plane: its bone objects and joints, in description order.
pub struct Ragdoll {
    /// (name, object) per bone.
    pub bones: Vec<(String, Object)>,
    /// (child bone's name, joint) per joint.
    pub joints: Vec<(String, Joint)>,
}

impl Ragdoll {
    /// The object of bone `name`.
    pub fn bone(&self, name: &str) -> Option<&Object> {
        self.bones.iter().find(|(n, _)| n == name).map(|(_, o)| o)
    }
}

fn invalid(field: String, message: String) -> Error {
    Error::Invalid { field, message }
}

fn conjugate(q: [f32; 4]) -> [f32; 4] {
    [-q[0], -q[1], -q[2], q[3]]
}

fn mul(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [
        a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
        a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
        a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
        a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
    ]
}

/// `pose · local`.
fn to_world(pose: &Pose, local: Vec3) -> Vec3 {
    let r = rotate(pose.rotation, local);
    [0, 1, 2].map(|k| pose.position[k] + r[k])
}

/// `pose⁻¹ · world`.
fn to_local(pose: &Pose, world: Vec3) -> Vec3 {
    rotate(
        conjugate(pose.rotation),
        [0, 1, 2].map(|k| world[k] - pose.position[k]),
    )
}

impl Bone {
    /// The capsule of the bone.
    pub fn shape(&self) -> Shape {
        Shape::Capsule {
            size: [2.0 * self.radius, self.length, 2.0 * self.radius],
        }
    }

    /// The joint's world point at rest.
    pub fn joint_point(&self) -> Vec3 {
        self.joint
            .unwrap_or_else(|| to_world(&self.pose, [0.0, self.length / 2.0, 0.0]))
    }
}

impl RagdollDesc {
    /// Checks every bone; errors name the bone and the field (`bones[3] "Head".Radius`).
    pub fn check(&self) -> Result<(), Error> {
        if self.bones.is_empty() {
            return Err(invalid(
                "bones".into(),
                "a ragdoll needs at least one bone".into(),
            ));
        }
        for (i, b) in self.bones.iter().enumerate() {
            let at = |f: &str| format!("bones[{}] {:?}.{f}", i + 1, b.name);
            if b.name.is_empty() {
                return Err(invalid(at("Name"), "a bone needs a name".into()));
            }
            if self.bones[..i].iter().any(|o| o.name == b.name) {
                return Err(invalid(
                    at("Name"),
                    format!("two bones are called {:?}", b.name),
                ));
            }
            if let Some(p) = &b.parent {
                if !self.bones[..i].iter().any(|o| &o.name == p) {
                    return Err(invalid(
                        at("Parent"),
                        format!("{p:?} is not a bone listed before this one"),
                    ));
                }
            }
            if !(b.radius.is_finite() && b.radius > 0.0) {
                return Err(invalid(
                    at("Radius"),
                    format!("must be > 0, got {}", b.radius),
                ));
            }
            if !(b.length.is_finite() && b.length >= 2.0 * b.radius) {
                return Err(invalid(
                    at("Length"),
                    format!(
                        "must be at least 2 × Radius = {}, got {}",
                        2.0 * b.radius,
                        b.length
                    ),
                ));
            }
            for (f, v) in [("SwingLimit", b.swing_limit), ("TwistLimit", b.twist_limit)] {
                if !(v.is_finite() && v > 0.0 && v <= std::f32::consts::PI) {
                    return Err(invalid(at(f), format!("must be in (0, π], got {v}")));
                }
            }
            shm_layout::validate::pose("CFrame", b.pose)
                .map_err(|e| invalid(at("CFrame"), e.detail().to_string()))?;
            if let Some(j) = b.joint {
                if j.iter().any(|c| !c.is_finite()) {
                    return Err(invalid(at("Joint"), format!("must be finite, got {j:?}")));
                }
            }
        }
        Ok(())
    }

    /// The joint of bone `i` to its parent: (parent index, ConeTwist options with the bone
    /// as object A). `None` for a root.
    pub fn joint_of(&self, i: usize) -> Option<(usize, Vec<JointProp>)> {
        let b = &self.bones[i];
        let parent = b.parent.as_ref()?;
        let p = self.bones.iter().position(|o| &o.name == parent)?;
        let point = b.joint_point();
        Some((
            p,
            vec![
                JointProp::AnchorA(to_local(&b.pose, point)),
                JointProp::AnchorB(to_local(&self.bones[p].pose, point)),
                JointProp::Axis([0.0, 1.0, 0.0]),
                JointProp::SwingLimit(b.swing_limit),
                JointProp::TwistLimit(b.twist_limit),
            ],
        ))
    }

    /// The default humanoid (15 bones, Roblox R15 names), standing, facing -Z, about
    /// 5.5 × `scale` tall, `pose` placing its LowerTorso centre (the root; the feet are
    /// 2.9 × `scale` below it). Limbs hang with their +Y end at the joint; the torso and
    /// head rise from theirs.
    pub fn humanoid(pose: Pose, scale: f32) -> RagdollDesc {
        let up = [0.0, 0.0, 0.0, 1.0];
        // Y along -Z (a foot pointing forward): -90° about X.
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let forward = [-h, 0.0, 0.0, h];
        // (name, parent, radius, length, centre, rotation, joint point, swing, twist)
        type Row = (
            String,
            Option<String>,
            f32,
            f32,
            Vec3,
            [f32; 4],
            Vec3,
            f32,
            f32,
        );
        let s = |n: &str| n.to_string();
        let mut rows: Vec<Row> = vec![
            (
                s("LowerTorso"),
                None,
                0.45,
                1.0,
                [0.0, 0.0, 0.0],
                up,
                [0.0; 3],
                1.0,
                1.0,
            ),
            (
                s("UpperTorso"),
                Some(s("LowerTorso")),
                0.5,
                1.4,
                [0.0, 1.2, 0.0],
                up,
                [0.0, 0.5, 0.0],
                0.5,
                0.4,
            ),
            (
                s("Head"),
                Some(s("UpperTorso")),
                0.45,
                1.0,
                [0.0, 2.45, 0.0],
                up,
                [0.0, 1.95, 0.0],
                0.6,
                1.0,
            ),
        ];
        for (side, x) in [("Left", -1.0f32), ("Right", 1.0)] {
            let name = |n: &str| format!("{side}{n}");
            let (ua, la, hand) = (name("UpperArm"), name("LowerArm"), name("Hand"));
            let (ul, ll, foot) = (name("UpperLeg"), name("LowerLeg"), name("Foot"));
            let ax = 0.9 * x;
            let lx = 0.35 * x;
            rows.extend([
                (
                    ua.clone(),
                    Some(s("UpperTorso")),
                    0.22,
                    0.9,
                    [ax, 1.3, 0.0],
                    up,
                    [ax, 1.75, 0.0],
                    1.4,
                    0.8,
                ),
                (
                    la.clone(),
                    Some(ua),
                    0.2,
                    0.8,
                    [ax, 0.45, 0.0],
                    up,
                    [ax, 0.85, 0.0],
                    1.2,
                    0.3,
                ),
                (
                    hand,
                    Some(la),
                    0.18,
                    0.5,
                    [ax, -0.2, 0.0],
                    up,
                    [ax, 0.05, 0.0],
                    0.7,
                    0.3,
                ),
                (
                    ul.clone(),
                    Some(s("LowerTorso")),
                    0.28,
                    1.0,
                    [lx, -1.0, 0.0],
                    up,
                    [lx, -0.5, 0.0],
                    1.2,
                    0.5,
                ),
                (
                    ll.clone(),
                    Some(ul),
                    0.24,
                    1.0,
                    [lx, -2.0, 0.0],
                    up,
                    [lx, -1.5, 0.0],
                    1.2,
                    0.3,
                ),
                (
                    foot,
                    Some(ll),
                    0.18,
                    0.8,
                    [lx, -2.7, -0.2],
                    forward,
                    [lx, -2.55, 0.0],
                    0.6,
                    0.3,
                ),
            ]);
        }
        let place = |local: Vec3| to_world(&pose, local.map(|c| c * scale));
        RagdollDesc {
            bones: rows
                .into_iter()
                .map(
                    |(name, parent, r, len, centre, rot, joint, swing, twist)| Bone {
                        joint: parent.as_ref().map(|_| place(joint)),
                        name,
                        parent,
                        radius: r * scale,
                        length: len * scale,
                        pose: Pose {
                            position: place(centre),
                            rotation: mul(pose.rotation, rot),
                        },
                        swing_limit: swing,
                        twist_limit: twist,
                    },
                )
                .collect(),
        }
    }
}

impl Plane {
    /// Builds `desc` (checked first): one capsule object per bone with [`BONE_PROPS`] then
    /// `props`, and a ConeTwist joint from each bone to its parent.
    pub fn ragdoll(&self, desc: &RagdollDesc, props: &[ObjectProp]) -> Result<Ragdoll, Error> {
        desc.check()?;
        let props: Vec<ObjectProp> = BONE_PROPS.iter().chain(props).copied().collect();
        let mut bones: Vec<(String, Object)> = Vec::new();
        for b in &desc.bones {
            bones.push((b.name.clone(), self.add(b.shape(), b.pose, &props)?));
        }
        let mut joints = Vec::new();
        for (i, b) in desc.bones.iter().enumerate() {
            if let Some((p, opts)) = desc.joint_of(i) {
                let j = self.joint(JointKind::ConeTwist, &bones[i].1, Some(&bones[p].1), &opts)?;
                joints.push((b.name.clone(), j));
            }
        }
        Ok(Ragdoll { bones, joints })
    }
}
