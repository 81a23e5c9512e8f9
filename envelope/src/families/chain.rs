//! Chains: `links` spheres (radius 0.4 · `link`) `link` apart, each joined to the one
//! before at the midpoint between them by a `Ball` or `Hinge` (axis z) joint, the first to
//! the world half a link before it (the issue's chain: anchors ±0.5 at link 1), the last
//! link `ratio` times heavier. Start pose: hanging straight down, horizontal
//! along +x, or coiled (folded in the xy plane, rows of 5 links one link apart). Solver:
//! what the plane chooses for a tree of such joints (an articulation), or impulse joints
//! (every joint given a BreakForce of 1e12, which it never reaches). Default gravity and
//! damping; stepped for [`RUN_S`].
//!
//! Oracle: the plane's worst joint error over every tick (`TickHeader::max_joint_error`) at
//! most 2 % of a link (`joint gap`; the docs' 1,000× chain claim is 0.01 at link 0.5).

use shm_layout::{JointKind, JointProp, ObjectProp, Pose, Shape};

use super::{draw_setting, plane_opts};
use crate::luau::{luau_prelude, lv, LUAU_END};
use crate::oracle::{at_most, finish, Outcome};
use crate::plane::{BuildResult, Run};
use crate::rng::{Rng, Span};
use crate::setting::{Setting, SettingRanges};
use crate::steps::{toward, toward_int};

/// The ranges a chain case is drawn from (their values: [`crate::space`]).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct ChainRanges {
    pub setting: SettingRanges,
    pub links: (u32, u32),
    pub ratio: Span,
    pub link: Span,
    pub poses: &'static [StartPose],
    pub kinds: &'static [Kind],
    pub solvers: &'static [Solver],
}

/// Simulated seconds a chain runs.
pub const RUN_S: f32 = 5.0;
/// Links per row of a coiled chain.
const ROW: usize = 5;

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum StartPose {
    Hanging,
    Horizontal,
    Coiled,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Kind {
    Ball,
    Hinge,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Solver {
    Articulation,
    Impulse,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Chain {
    pub setting: Setting,
    pub links: u32,
    pub ratio: f64,
    pub link: f64,
    pub pose: StartPose,
    pub kind: Kind,
    pub solver: Solver,
}

impl Chain {
    pub fn draw(rng: &mut Rng, r: &ChainRanges) -> Chain {
        Chain {
            setting: draw_setting(rng, &r.setting),
            links: rng.int_log(r.links.0, r.links.1),
            ratio: rng.log_uniform(r.ratio),
            link: rng.log_uniform(r.link),
            pose: rng.pick(r.poses),
            kind: rng.pick(r.kinds),
            solver: rng.pick(r.solvers),
        }
    }

    pub fn tol(&self) -> f64 {
        0.02 * self.link
    }

    /// Link centres; the world anchor is the first.
    pub fn positions(&self) -> Vec<[f64; 3]> {
        let (l, y0) = (
            self.link,
            20.0 * self.link.max(1.0) + self.links as f64 * self.link,
        );
        (0..self.links as usize)
            .map(|i| match self.pose {
                StartPose::Hanging => [0.0, y0 - i as f64 * l, 0.0],
                StartPose::Horizontal => [i as f64 * l, y0, 0.0],
                StartPose::Coiled => {
                    let (row, col) = (i / ROW, i % ROW);
                    let x = if row % 2 == 0 { col } else { ROW - 1 - col };
                    [x as f64 * l, y0 - row as f64 * l, 0.0]
                }
            })
            .collect()
    }

    /// The point link `i` is joined to: the link before, or for the first a point one link
    /// back (above a hanging chain, behind a horizontal or coiled one).
    fn before(&self, i: usize, pos: &[[f64; 3]]) -> [f64; 3] {
        if i > 0 {
            return pos[i - 1];
        }
        let p = pos[0];
        match self.pose {
            StartPose::Hanging => [p[0], p[1] + self.link, p[2]],
            _ => [p[0] - self.link, p[1], p[2]],
        }
    }

    fn kind_name(&self) -> &'static str {
        match self.kind {
            Kind::Ball => "Ball",
            Kind::Hinge => "Hinge",
        }
    }

    pub fn run(&self) -> BuildResult<Outcome> {
        let mut run = Run::new(&self.setting, &[])?;
        let pos = self.positions();
        let n = pos.len();
        let mut prev = None;
        for (i, p) in pos.iter().enumerate() {
            let w = if i + 1 == n { self.ratio } else { 1.0 };
            let h = run.add(
                Shape::Sphere {
                    radius: (0.4 * self.link) as f32,
                },
                Pose::at(p.map(|v| v as f32)),
                &[
                    ObjectProp::HitBoxQuality(self.setting.quality),
                    ObjectProp::Weight(w as f32),
                ],
            )?;
            let q = self.before(i, &pos);
            let mid = [
                (p[0] + q[0]) / 2.0,
                (p[1] + q[1]) / 2.0,
                (p[2] + q[2]) / 2.0,
            ];
            let anchor_a = [mid[0] - p[0], mid[1] - p[1], mid[2] - p[2]];
            let anchor_b = match prev {
                None => mid,
                Some(_) => [mid[0] - q[0], mid[1] - q[1], mid[2] - q[2]],
            };
            let mut props = vec![
                JointProp::AnchorA(anchor_a.map(|v| v as f32)),
                JointProp::AnchorB(anchor_b.map(|v| v as f32)),
            ];
            if self.kind == Kind::Hinge {
                props.push(JointProp::Axis([0.0, 0.0, 1.0]));
            }
            if self.solver == Solver::Impulse {
                props.push(JointProp::BreakForce(1e12));
            }
            let kind = match self.kind {
                Kind::Ball => JointKind::Ball,
                Kind::Hinge => JointKind::Hinge,
            };
            run.joint(kind, h, prev, props)?;
            prev = Some(h);
        }
        let mut worst = 0.0f64;
        for _ in 0..run.ticks_for(RUN_S) {
            run.step()?;
            let e = run.plane.header().max_joint_error as f64;
            worst = if e.is_nan() { f64::NAN } else { worst.max(e) };
        }
        let mut v = Vec::new();
        at_most(&mut v, "joint gap", worst, self.tol());
        Ok(finish(&run, v))
    }

    pub fn simpler(&self) -> Vec<Chain> {
        let mut out = Vec::new();
        for s in self.setting.simpler() {
            out.push(Chain {
                setting: s,
                ..self.clone()
            });
        }
        for n in toward_int(self.links, 2) {
            out.push(Chain {
                links: n,
                ..self.clone()
            });
        }
        if self.pose != StartPose::Hanging {
            out.push(Chain {
                pose: StartPose::Hanging,
                ..self.clone()
            });
            if self.pose == StartPose::Coiled {
                out.push(Chain {
                    pose: StartPose::Horizontal,
                    ..self.clone()
                });
            }
        }
        if self.kind != Kind::Ball {
            out.push(Chain {
                kind: Kind::Ball,
                ..self.clone()
            });
        }
        if self.solver != Solver::Articulation {
            out.push(Chain {
                solver: Solver::Articulation,
                ..self.clone()
            });
        }
        for r in toward(self.ratio, 1.0) {
            out.push(Chain {
                ratio: r,
                ..self.clone()
            });
        }
        for l in toward(self.link, 1.0) {
            out.push(Chain {
                link: l,
                ..self.clone()
            });
        }
        out
    }

    pub fn luau(&self) -> String {
        let pos = self.positions();
        let list: Vec<String> = pos.iter().map(|p| lv(*p)).collect();
        let mut s = luau_prelude(
            &format!(
                "a {:?} chain of {} {} links {} apart, last {}× heavier, {:?} joints",
                self.pose,
                self.links,
                self.kind_name(),
                self.link,
                self.ratio,
                self.solver
            ),
            &format!("{self:?}"),
            &plane_opts(&self.setting, ""),
            self.setting.tick_rate,
        );
        let extra = match (self.kind, self.solver) {
            (Kind::Hinge, Solver::Impulse) => ", Axis = Vector.new(0, 0, 1), BreakForce = 1e12",
            (Kind::Hinge, Solver::Articulation) => ", Axis = Vector.new(0, 0, 1)",
            (Kind::Ball, Solver::Impulse) => ", BreakForce = 1e12",
            (Kind::Ball, Solver::Articulation) => "",
        };
        s += &format!(
            r#"local L, Q, RATIO, TOL = {link}, {q}, {ratio}, {tol}
local at = {{ {list} }}
local before = {before0}
local links, joints = {{}}, {{}}
for i, p in at do
	links[i] = basic("Sphere", Vector.new(0.8 * L, 0.8 * L, 0.8 * L), CFrame.new(p.X, p.Y, p.Z), {{ {{ "HitBoxQuality", Q }}, {{ "Weight", if i == #at then RATIO else 1 }} }})
	local q = if i == 1 then before else at[i - 1]
	local mid = (p + q) * 0.5
	joints[i] = world:NewJoint("{kind}", links[i], if i == 1 then nil else links[i - 1], {{ AnchorA = mid - p, AnchorB = if i == 1 then mid else mid - q{extra} }})
end
local worst, nonFinite = 0, 0
for _ = 1, {ticks} do
	world:Step(DT)
	for _, j in joints do
		local e = j.Error
		worst = if e ~= e then e else math.max(worst, e)
	end
	for _, o in links do
		if not finite(o) then
			nonFinite += 1
		end
	end
end
local last = links[#links].CFrame.Position
print(string.format("last link at (%.3f, %.3f, %.3f)", last.X, last.Y, last.Z))
check("non-finite body-ticks", nonFinite, 0)
check("worst joint error", worst, TOL)
"#,
            link = self.link,
            q = self.setting.quality,
            ratio = self.ratio,
            tol = self.tol(),
            list = list.join(", "),
            before0 = lv(self.before(0, &pos)),
            kind = self.kind_name(),
            ticks = (RUN_S * self.setting.tick_rate).round() as u64,
        );
        s + LUAU_END
    }
}
