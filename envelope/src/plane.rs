//! [`Run`]: one case's plane (the daemon's own plane code, in process) stepped at a fixed
//! dt, with what every oracle needs recorded on each tick: the first non-finite body, and
//! a running fold of the tick headers' `state_hash` (the determinism oracle compares it
//! across two runs of the same case).

use physics_daemon::backend::Backend;
use physics_scenes::LocalPlane;
use shm_layout::{
    BodyState, Handle, JointKind, JointOp, JointProp, ObjectProp, PlaneOp, PlaneProp, Pose, Reply,
    Shape,
};

use crate::setting::Setting;

/// A case's plane and its per-tick records.
pub struct Run {
    pub plane: LocalPlane,
    pub dt: f32,
    pub ticks: u64,
    /// The first tick (1-based) after which some body was non-finite.
    pub non_finite_at: Option<u64>,
    /// FNV-style fold of every tick's `state_hash`.
    pub hash: u64,
}

/// Why a case could not even be built (a refused option is a bug of the case, reported as
/// such rather than as a physics failure).
pub type BuildResult<T> = Result<T, String>;

impl Run {
    /// A manual plane (TickRate 0, stepped at `1 / setting.tick_rate`) with the setting's
    /// SolverIterations, then `props`.
    pub fn new(setting: &Setting, props: &[PlaneProp]) -> BuildResult<Run> {
        let mut all = vec![
            PlaneProp::TickRate(0.0),
            PlaneProp::SolverIterations(setting.iterations),
        ];
        all.extend_from_slice(props);
        Ok(Run {
            plane: LocalPlane::new(1, &all).map_err(|e| e.to_string())?,
            dt: 1.0 / setting.tick_rate,
            ticks: 0,
            non_finite_at: None,
            hash: 0xcbf2_9ce4_8422_2325,
        })
    }

    pub fn add(&mut self, shape: Shape, pose: Pose, props: &[ObjectProp]) -> BuildResult<Handle> {
        self.plane
            .add_object(&shape, pose, props)
            .map_err(|e| format!("add {shape:?}: {e}"))
    }

    /// Creates a joint; returns its handle.
    pub fn joint(
        &mut self,
        kind: JointKind,
        a: Handle,
        b: Option<Handle>,
        props: Vec<JointProp>,
    ) -> BuildResult<Handle> {
        match Backend::apply(
            &mut self.plane,
            PlaneOp::Joint(JointOp::Create { kind, a, b, props }),
        ) {
            Ok(Reply::Joint { handle, .. }) => Ok(handle),
            Ok(other) => Err(format!("joint create replied {other:?}")),
            Err(e) => Err(format!("joint create: {e}")),
        }
    }

    /// One tick; records non-finite bodies and folds the state hash.
    pub fn step(&mut self) -> BuildResult<()> {
        self.plane.step(self.dt).map_err(|e| format!("step: {e}"))?;
        self.ticks += 1;
        let header = self.plane.header();
        self.hash = (self.hash ^ header.state_hash).wrapping_mul(0x0100_0000_01b3);
        if self.non_finite_at.is_none()
            && !(0..self.plane.slot_count()).all(|i| self.plane.body_state(i).is_finite())
        {
            self.non_finite_at = Some(self.ticks);
        }
        Ok(())
    }

    /// Ticks covering `seconds` (at least one).
    pub fn ticks_for(&self, seconds: f32) -> u64 {
        ((seconds / self.dt).round() as u64).max(1)
    }

    pub fn state(&self, h: Handle) -> BodyState {
        self.plane.body_state(h.slot as usize)
    }

    pub fn time(&self) -> f64 {
        self.ticks as f64 * self.dt as f64
    }
}

/// Unit quaternion `[x, y, z, w]` for `angle` radians about the z axis.
pub fn about_z(angle: f32) -> [f32; 4] {
    let (s, c) = (angle / 2.0).sin_cos();
    [0.0, 0.0, s, c]
}

/// `v` rotated by the unit quaternion `q` (`[x, y, z, w]`).
pub fn rotate(q: [f32; 4], v: [f32; 3]) -> [f64; 3] {
    let [x, y, z, w] = q.map(|c| c as f64);
    let v = v.map(|c| c as f64);
    // t = 2 q×v; v' = v + w t + q×t
    let t = [
        2.0 * (y * v[2] - z * v[1]),
        2.0 * (z * v[0] - x * v[2]),
        2.0 * (x * v[1] - y * v[0]),
    ];
    [
        v[0] + w * t[0] + (y * t[2] - z * t[1]),
        v[1] + w * t[1] + (z * t[0] - x * t[2]),
        v[2] + w * t[2] + (x * t[1] - y * t[0]),
    ]
}

/// `v` rotated by the inverse of `q`.
pub fn unrotate(q: [f32; 4], v: [f32; 3]) -> [f64; 3] {
    rotate([-q[0], -q[1], -q[2], q[3]], v)
}

pub fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

pub fn sub(a: [f32; 3], b: [f32; 3]) -> [f64; 3] {
    [
        a[0] as f64 - b[0] as f64,
        a[1] as f64 - b[1] as f64,
        a[2] as f64 - b[2] as f64,
    ]
}
