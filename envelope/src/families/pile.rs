//! Piles: `count` parts of side `size` (cubes; with `round`, every third an upright
//! cylinder and every third a sphere) dropped in a loose grid, layer over layer, onto an anchored floor whose
//! top centre is `offset` from the origin along every axis (far from the origin: f32
//! spacing there is `offset · 2⁻²³`). Default gravity and damping; run for [`SETTLE_S`] at
//! the case's tick rate (high and low).
//!
//! Oracles: no part's centre ever below the floor's top (`passes the floor`, checked every
//! tick); after [`SETTLE_S`] the plane's deepest contact at most `0.02 + 0.02 · size + 16
//! ulp(offset)` (`penetration`) and, in a pile of cubes only, every part asleep (`sleeps`:
//! a ball or a toppled cylinder rolling on a flat floor keeps rolling, damped only by the
//! plane's damping, so a round pile is not asked to sleep).

use shm_layout::{ObjectProp, Pose, Shape};

use super::{draw_setting, plane_opts};
use crate::luau::{luau_prelude, lv, LUAU_END};
use crate::oracle::{at_most, finish, Outcome};
use crate::plane::{BuildResult, Run};
use crate::rng::{round3, Rng, Span};
use crate::setting::{Setting, SettingRanges};
use crate::steps::{toward, toward_int};

/// The ranges a pile case is drawn from (their values: [`crate::space`]).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct PileRanges {
    pub setting: SettingRanges,
    pub count: (u32, u32),
    pub size: Span,
    /// Distance of the floor from the origin along each axis, log-uniform ...
    pub offset: Span,
    /// ... except this share of cases, at the origin.
    pub at_origin: f64,
    /// Whether the pile has round parts (spheres, cylinders).
    pub round: &'static [bool],
}

/// Simulated seconds a pile has to settle and sleep.
pub const SETTLE_S: f32 = 8.0;
/// Parts per side of a layer.
const SIDE: usize = 3;

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Pile {
    pub setting: Setting,
    pub count: u32,
    pub size: f64,
    pub offset: f64,
    pub round: bool,
}

impl Pile {
    pub fn draw(rng: &mut Rng, r: &PileRanges) -> Pile {
        Pile {
            setting: draw_setting(rng, &r.setting),
            count: rng.int(r.count.0, r.count.1),
            size: rng.log_uniform(r.size),
            offset: if rng.unit() < r.at_origin {
                0.0
            } else {
                rng.log_uniform(r.offset)
            },
            round: rng.pick(r.round),
        }
    }

    fn origin(&self) -> [f64; 3] {
        [self.offset; 3]
    }

    /// Shape name and start position (relative to the origin) of part `i`: a grid of
    /// SIDE × SIDE per layer, 1.6 sides apart, layers 1.5 sides apart, each nudged by a
    /// fixed pattern of up to 0.3 sides so layers do not sit exactly on one another.
    fn part(&self, i: usize) -> (&'static str, [f64; 3]) {
        let s = self.size;
        let (layer, k) = (i / (SIDE * SIDE), i % (SIDE * SIDE));
        let (gx, gz) = ((k % SIDE) as f64 - 1.0, (k / SIDE) as f64 - 1.0);
        let nudge = |j: usize| (((j * 7919 + layer * 104729) % 61) as f64 / 61.0 - 0.5) * 0.6;
        let p = [
            (gx * 1.6 + nudge(i)) * s,
            s * (1.0 + 1.5 * layer as f64),
            (gz * 1.6 + nudge(i + 17)) * s,
        ];
        let shape = match i % 3 {
            2 if self.round => "Sphere",
            1 if self.round => "Cylinder",
            _ => "Cube",
        };
        (shape, p)
    }

    fn floor(&self) -> ([f64; 3], f64) {
        let side = (30.0 * self.size).max(200.0);
        let thick = self.size.max(1.0);
        ([side, thick, side], -thick / 2.0)
    }

    fn tol(&self) -> f64 {
        0.02 + 0.02 * self.size + 16.0 * self.offset * f32::EPSILON as f64
    }

    pub fn run(&self) -> BuildResult<Outcome> {
        let mut run = Run::new(&self.setting, &[])?;
        let o = self.origin();
        let (fs, fy) = self.floor();
        run.add(
            Shape::Cube {
                size: fs.map(|v| v as f32),
            },
            Pose::at([o[0] as f32, (o[1] + fy) as f32, o[2] as f32]),
            &[ObjectProp::Anchored(true)],
        )?;
        let s = self.size as f32;
        let mut parts = Vec::new();
        for i in 0..self.count as usize {
            let (name, p) = self.part(i);
            let shape = match name {
                "Sphere" => Shape::Sphere { radius: s / 2.0 },
                "Cylinder" => Shape::Cylinder { size: [s; 3] },
                _ => Shape::Cube { size: [s; 3] },
            };
            parts.push(run.add(
                shape,
                Pose::at([
                    (o[0] + p[0]) as f32,
                    (o[1] + p[1]) as f32,
                    (o[2] + p[2]) as f32,
                ]),
                &[ObjectProp::HitBoxQuality(self.setting.quality)],
            )?);
        }
        let floor_top = (o[1] as f32) as f64;
        let mut below = 0usize;
        for _ in 0..run.ticks_for(SETTLE_S) {
            run.step()?;
            below += parts
                .iter()
                .filter(|h| (run.state(**h).position[1] as f64) < floor_top)
                .count();
        }
        let awake = parts
            .iter()
            .filter(|h| !run.state(**h).is_sleeping())
            .count();
        let mut v = Vec::new();
        at_most(&mut v, "passes the floor", below as f64, 0.0);
        at_most(
            &mut v,
            "penetration",
            run.plane.header().max_penetration as f64,
            self.tol(),
        );
        if !self.round {
            at_most(&mut v, "sleeps", awake as f64, 0.0);
        }
        Ok(finish(&run, v))
    }

    pub fn simpler(&self) -> Vec<Pile> {
        let mut out = Vec::new();
        for s in self.setting.simpler() {
            out.push(Pile {
                setting: s,
                ..self.clone()
            });
        }
        for c in toward_int(self.count, 1) {
            out.push(Pile {
                count: c,
                ..self.clone()
            });
        }
        if self.round {
            out.push(Pile {
                round: false,
                ..self.clone()
            });
        }
        if self.offset != 0.0 {
            out.push(Pile {
                offset: 0.0,
                ..self.clone()
            });
            let half = round3(self.offset / 10.0);
            if half >= 1.0 {
                out.push(Pile {
                    offset: half,
                    ..self.clone()
                });
            }
        }
        for s in toward(self.size, 1.0) {
            out.push(Pile {
                size: s,
                ..self.clone()
            });
        }
        out
    }

    pub fn luau(&self) -> String {
        let o = self.origin();
        let (fs, fy) = self.floor();
        let mut s = luau_prelude(
            &format!(
                "a pile of {} parts of side {} at {} from the origin",
                self.count, self.size, self.offset
            ),
            &format!("{self:?}"),
            &plane_opts(&self.setting, ""),
            self.setting.tick_rate,
        );
        let list: Vec<String> = (0..self.count as usize)
            .map(|i| {
                let (name, p) = self.part(i);
                format!("{{ \"{name}\", {} }}", lv(p))
            })
            .collect();
        s += &format!(
            r#"local O, S, Q, ROUND = {origin}, {size}, {q}, {round}
basic("Cube", Vector.new({fx}, {fyy}, {fz}), CFrame.new(O.X, O.Y + {fy}, O.Z), {{ {{ "Anchored", true }} }})
local spec = {{ {list} }}
local parts = {{}}
for i, sp in spec do
	local p = O + sp[2]
	parts[i] = basic(sp[1], Vector.new(S, S, S), CFrame.new(p.X, p.Y, p.Z), {{ {{ "HitBoxQuality", Q }} }})
end
local below, nonFinite = 0, 0
for _ = 1, {ticks} do
	world:Step(DT)
	for _, o in parts do
		if o.CFrame.Position.Y < O.Y then
			below += 1
		end
		if not finite(o) then
			nonFinite += 1
		end
	end
end
local awake = 0
for _, o in parts do
	awake += if o.Sleeping then 0 else 1
end
check("non-finite body-ticks", nonFinite, 0)
check("part-ticks below the floor's top", below, 0)
if not ROUND then
	check("parts awake", awake, 0)
end
"#,
            origin = lv(o),
            size = self.size,
            q = self.setting.quality,
            round = self.round,
            fx = fs[0],
            fyy = fs[1],
            fz = fs[2],
            list = list.join(", "),
            ticks = (SETTLE_S * self.setting.tick_rate).round() as u64,
        );
        s + LUAU_END
    }
}
