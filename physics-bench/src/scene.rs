//! The benchmark scenes. Each is one list of objects and plane options, built the same way in
//! a daemon plane (through the client) and in an in-process plane (the daemon's own plane
//! code), so both sides step exactly the same world with exactly the same settings.

use client_sdk::{BodyState, PlaneProp};
use physics_scenes::{LocalPlane, SceneTarget};

use super::error::BenchResult;

/// Every tick advances by the same dt: rapier's sleep logic wants a fixed step.
pub const DT: f32 = 1.0 / 60.0;

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

    /// The scene's objects, added to `target` (the pile's floor first).
    fn build<T: SceneTarget>(&self, target: &mut T) -> Result<Vec<T::Handle>, T::Error> {
        match self.kind {
            Kind::Pile => physics_scenes::pile(target, self.bodies),
            Kind::Free => physics_scenes::free_bodies(target, self.bodies),
        }
    }

    /// The same scene in process, with the daemon's own plane code.
    pub fn build_local(&self, threads: u32) -> BenchResult<LocalPlane> {
        let mut plane = LocalPlane::new(1, &self.plane_props(threads))?;
        self.build(&mut plane)?;
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
        let objects = self.build(&mut &plane)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use physics_scenes::Spawn;

    #[test]
    fn scenes_have_the_asked_body_count() {
        for n in [1, 7, 100, 1000] {
            let count = |kind| {
                let mut spawns: Vec<Spawn> = Vec::new();
                let _ = Scene { kind, bodies: n }.build(&mut spawns);
                spawns.len()
            };
            assert_eq!(count(Kind::Pile), n + 1, "pile has a floor on top");
            assert_eq!(count(Kind::Free), n);
        }
    }
}
