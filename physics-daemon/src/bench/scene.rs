//! The benchmark scenes. Each is one list of objects and plane options, built the same way in
//! a daemon plane (through the client) and in an in-process plane (the daemon's own plane
//! code), so both sides step exactly the same world with exactly the same settings.

use client_sdk::{BodyState, ObjectProp, PlaneProp, Pose, Shape};
use physics_daemon::plane::Plane as LocalPlane;

use super::error::BenchResult;

/// Every tick advances by the same dt: rapier's sleep logic wants a fixed step.
pub const DT: f32 = 1.0 / 60.0;
/// Cubes per column of the pile.
const PILE_HEIGHT: usize = 5;
/// Distance between pile columns (cubes are 1 unit wide; columns do not touch).
const PILE_SPACING: f32 = 1.25;
/// Distance between free-flying bodies.
const FREE_SPACING: f32 = 3.0;

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// Columns of unit cubes resting on an anchored floor, stepped until rapier puts them to
    /// sleep: the settled world most of a game level is.
    Pile,
    /// Cubes on a sparse grid with random velocities and no gravity: everything awake and
    /// moving, few contacts.
    Free,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Pile => "pile",
            Kind::Free => "free",
        }
    }
}

#[derive(Debug, Clone, Copy)]
pub struct Scene {
    pub kind: Kind,
    /// Dynamic bodies (the pile's floor comes on top).
    pub bodies: usize,
}

/// One object to create.
pub struct Spawn {
    pub shape: Shape,
    pub pose: Pose,
    pub props: Vec<ObjectProp>,
}

impl Scene {
    /// Manual planes: the bench decides when a tick happens.
    pub fn plane_props(&self, threads: u32) -> Vec<PlaneProp> {
        let mut props = vec![PlaneProp::TickRate(0.0), PlaneProp::Threads(threads)];
        if self.kind == Kind::Free {
            props.push(PlaneProp::Gravity([0.0; 3]));
        }
        props
    }

    /// Ticks stepped after building and before measuring.
    pub fn settle_ticks(&self) -> usize {
        match self.kind {
            // rapier lets a body sleep after 2 s of rest; give it 3 s.
            Kind::Pile => 180,
            Kind::Free => 5,
        }
    }

    pub fn spawns(&self) -> Vec<Spawn> {
        match self.kind {
            Kind::Pile => self.pile(),
            Kind::Free => self.free(),
        }
    }

    fn pile(&self) -> Vec<Spawn> {
        let columns = self.bodies.div_ceil(PILE_HEIGHT);
        let side = (columns as f64).sqrt().ceil() as usize;
        let width = side as f32 * PILE_SPACING;
        let mut out = Vec::with_capacity(self.bodies + 1);
        out.push(Spawn {
            shape: Shape::Cube {
                size: [width + 2.0, 1.0, width + 2.0],
            },
            pose: Pose::at([width / 2.0, -0.5, width / 2.0]),
            props: vec![ObjectProp::Anchored(true)],
        });
        for i in 0..self.bodies {
            let (column, layer) = (i / PILE_HEIGHT, i % PILE_HEIGHT);
            let x = (column % side) as f32 * PILE_SPACING + 0.5;
            let z = (column / side) as f32 * PILE_SPACING + 0.5;
            out.push(Spawn {
                shape: Shape::Cube { size: [1.0; 3] },
                pose: Pose::at([x, 0.5 + layer as f32, z]),
                props: Vec::new(),
            });
        }
        out
    }

    fn free(&self) -> Vec<Spawn> {
        let side = (self.bodies as f64).cbrt().ceil() as usize;
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        (0..self.bodies)
            .map(|i| {
                let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
                Spawn {
                    shape: Shape::Cube { size: [1.0; 3] },
                    pose: Pose::at([x as f32, y as f32, z as f32].map(|c| c * FREE_SPACING)),
                    props: vec![
                        ObjectProp::Velocity([rng.unit(), rng.unit(), rng.unit()]),
                        ObjectProp::AngularVelocity([rng.unit(), rng.unit(), rng.unit()]),
                    ],
                }
            })
            .collect()
    }

    /// The same scene in process, with the daemon's own plane code.
    pub fn build_local(&self, threads: u32) -> BenchResult<LocalPlane> {
        let mut plane = LocalPlane::new(1, 0, &self.plane_props(threads))?;
        for s in self.spawns() {
            plane.add_object(&s.shape, s.pose, &s.props)?;
        }
        Ok(plane)
    }

    /// The same scene in a daemon plane owned by `client`, with its objects in spawn order.
    pub fn build_remote(
        &self,
        client: &client_sdk::Client,
        threads: u32,
    ) -> BenchResult<(client_sdk::Plane, Vec<client_sdk::Object>)> {
        let props = self.plane_props(threads);
        let options = client_sdk::PlaneOptions {
            gravity: props.iter().find_map(|p| match p {
                PlaneProp::Gravity(g) => Some(*g),
                _ => None,
            }),
            threads: Some(threads),
            tick_rate: Some(0.0),
            ..Default::default()
        };
        let plane = client.create_plane(&options)?;
        let mut objects = Vec::with_capacity(self.bodies + 1);
        for s in self.spawns() {
            objects.push(plane.add(s.shape, s.pose, &s.props)?);
        }
        Ok((plane, objects))
    }
}

/// What a reader does with every pose: read position and rotation.
pub fn touch(bodies: &[BodyState]) -> f32 {
    bodies
        .iter()
        .map(|b| b.position[0] + b.position[1] + b.position[2] + b.rotation[3])
        .sum()
}

/// Share of live bodies rapier has put to sleep.
pub fn asleep_fraction(bodies: &[BodyState]) -> f64 {
    let live = bodies.iter().filter(|b| b.is_alive() && !b.is_anchored());
    let (n, asleep) = live.fold((0usize, 0usize), |(n, a), b| {
        (n + 1, a + usize::from(b.is_sleeping()))
    });
    if n == 0 {
        0.0
    } else {
        asleep as f64 / n as f64
    }
}

/// xorshift64*: deterministic velocities without a dependency.
struct Rng(u64);

impl Rng {
    /// Uniform in [-1, 1).
    fn unit(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40;
        bits as f32 / (1u64 << 23) as f32 - 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scenes_have_the_asked_body_count() {
        for n in [1, 7, 100, 1000] {
            let pile = Scene {
                kind: Kind::Pile,
                bodies: n,
            };
            assert_eq!(pile.spawns().len(), n + 1, "pile has a floor on top");
            let free = Scene {
                kind: Kind::Free,
                bodies: n,
            };
            assert_eq!(free.spawns().len(), n);
        }
    }

    #[test]
    fn random_velocities_stay_in_range() {
        let mut rng = Rng(1);
        for _ in 0..10_000 {
            let v = rng.unit();
            assert!((-1.0..1.0).contains(&v), "{v}");
        }
    }
}
