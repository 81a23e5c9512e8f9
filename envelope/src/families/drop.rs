//! Drops: one body set down flat (unrotated; a capsule lying along x) with its lowest point
//! `height` above an anchored floor, default gravity and damping, judged [`REST_S`] after
//! it lands. Shapes: cube, sphere, upright cylinder, lying capsule, square-pyramid mesh
//! part, wedge; width `size`, height `size · aspect` (a cube's and sphere's aspect is 1).
//!
//! Oracles (tolerances: `0.005 + 0.02 · size` sideways, `0.03 + 0.02 · size` in height):
//! its up axis within 2° of vertical (`upright`), its centre within the sideways tolerance
//! of where it was dropped (`in place`), and at its exact resting height (`rests`).

use shm_layout::{ObjectProp, Pose, Shape};

use super::{draw_setting, plane_opts, tilt_deg};
use crate::luau::{luau_prelude, lv, LUAU_END};
use crate::oracle::{at_most, finish, Outcome};
use crate::plane::{about_z, BuildResult, Run};
use crate::rng::{Rng, Span};
use crate::setting::{Setting, SettingRanges};
use crate::steps::toward;

/// The ranges a drop case is drawn from (their values: [`crate::space`]).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct DropRanges {
    pub setting: SettingRanges,
    pub shapes: &'static [DropShape],
    pub size: Span,
    pub aspect: Span,
    pub height: Span,
}

/// Simulated seconds after landing before the body is judged.
pub const REST_S: f32 = 3.0;

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum DropShape {
    Cube,
    Sphere,
    Cylinder,
    Capsule,
    Pyramid,
    Wedge,
}

pub const ALL_SHAPES: [DropShape; 6] = [
    DropShape::Cube,
    DropShape::Sphere,
    DropShape::Cylinder,
    DropShape::Capsule,
    DropShape::Pyramid,
    DropShape::Wedge,
];

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Drop {
    pub setting: Setting,
    pub shape: DropShape,
    pub size: f64,
    pub aspect: f64,
    pub height: f64,
}

impl Drop {
    pub fn draw(rng: &mut Rng, r: &DropRanges) -> Drop {
        Drop {
            setting: draw_setting(rng, &r.setting),
            shape: rng.pick(r.shapes),
            size: rng.log_uniform(r.size),
            aspect: rng.log_uniform(r.aspect),
            height: rng.log_uniform(r.height),
        }
    }

    /// The part's Size (x, y, z) as built, before any rotation.
    fn dims(&self) -> [f64; 3] {
        let (w, a) = (self.size, self.aspect);
        match self.shape {
            DropShape::Cube | DropShape::Sphere => [w, w, w],
            DropShape::Capsule => [w, w * a.max(1.0) + w, w],
            _ => [w, w * a, w],
        }
    }

    /// Centre height at rest on the floor (top at y = 0).
    fn rest(&self) -> f64 {
        let d = self.dims();
        match self.shape {
            DropShape::Sphere | DropShape::Capsule => d[0] / 2.0,
            _ => d[1] / 2.0,
        }
    }

    fn rotation(&self) -> [f32; 4] {
        match self.shape {
            DropShape::Capsule => about_z(std::f32::consts::FRAC_PI_2),
            _ => [0.0, 0.0, 0.0, 1.0],
        }
    }

    /// The body-local axis that starts vertical.
    fn local_up(&self) -> [f32; 3] {
        match self.shape {
            DropShape::Capsule => [1.0, 0.0, 0.0],
            _ => [0.0, 1.0, 0.0],
        }
    }

    /// A square pyramid filling its Size box, centred on it (base at -y/2, apex at +y/2).
    fn pyramid(d: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let (x, y, z) = (d[0] / 2.0, d[1] / 2.0, d[2] / 2.0);
        (
            vec![
                [-x, -y, -z],
                [x, -y, -z],
                [x, -y, z],
                [-x, -y, z],
                [0.0, y, 0.0],
            ],
            vec![
                [0, 1, 2],
                [0, 2, 3],
                [0, 4, 1],
                [1, 4, 2],
                [2, 4, 3],
                [3, 4, 0],
            ],
        )
    }

    fn shape(&self) -> Shape {
        let d = self.dims();
        let size = d.map(|v| v as f32);
        match self.shape {
            DropShape::Cube => Shape::Cube { size },
            DropShape::Sphere => Shape::Sphere {
                radius: size[0] / 2.0,
            },
            DropShape::Cylinder => Shape::Cylinder { size },
            DropShape::Capsule => Shape::Capsule { size },
            DropShape::Wedge => Shape::Wedge { size },
            DropShape::Pyramid => {
                let (v, t) = Self::pyramid(d);
                Shape::Mesh {
                    vertices: v.into_iter().map(|p| p.map(|c| c as f32)).collect(),
                    triangles: t,
                }
            }
        }
    }

    fn floor(&self) -> ([f64; 3], f64) {
        let side = (20.0 * self.size).max(200.0);
        let thick = self.size.max(1.0);
        ([side, thick, side], -thick / 2.0)
    }

    fn ticks(&self) -> u64 {
        let fall = (2.0 * self.height / 50.0).sqrt();
        ((fall + REST_S as f64) * self.setting.tick_rate as f64).round() as u64
    }

    fn tol_side(&self) -> f64 {
        0.005 + 0.02 * self.size
    }

    fn tol_height(&self) -> f64 {
        0.03 + 0.02 * self.size
    }

    pub fn run(&self) -> BuildResult<Outcome> {
        let mut run = Run::new(&self.setting, &[])?;
        let (fs, fy) = self.floor();
        run.add(
            Shape::Cube {
                size: fs.map(|v| v as f32),
            },
            Pose::at([0.0, fy as f32, 0.0]),
            &[ObjectProp::Anchored(true)],
        )?;
        let y0 = self.rest() + self.height;
        let body = run.add(
            self.shape(),
            Pose {
                position: [0.0, y0 as f32, 0.0],
                rotation: self.rotation(),
            },
            &[ObjectProp::HitBoxQuality(self.setting.quality)],
        )?;
        for _ in 0..self.ticks() {
            run.step()?;
        }
        let st = run.state(body);
        let p = st.position.map(|v| v as f64);
        let mut v = Vec::new();
        at_most(
            &mut v,
            "upright",
            tilt_deg(st.rotation, self.local_up()),
            2.0,
        );
        at_most(
            &mut v,
            "in place",
            (p[0] * p[0] + p[2] * p[2]).sqrt(),
            self.tol_side(),
        );
        at_most(
            &mut v,
            "rests",
            (p[1] - self.rest()).abs(),
            self.tol_height(),
        );
        Ok(finish(&run, v))
    }

    pub fn simpler(&self) -> Vec<Drop> {
        let mut out = Vec::new();
        for s in self.setting.simpler() {
            out.push(Drop {
                setting: s,
                ..self.clone()
            });
        }
        if self.shape != DropShape::Cube {
            out.push(Drop {
                shape: DropShape::Cube,
                ..self.clone()
            });
        }
        for h in toward(self.height, 1.0) {
            out.push(Drop {
                height: h,
                ..self.clone()
            });
        }
        for s in toward(self.size, 1.0) {
            out.push(Drop {
                size: s,
                ..self.clone()
            });
        }
        for a in toward(self.aspect, 1.0) {
            out.push(Drop {
                aspect: a,
                ..self.clone()
            });
        }
        out
    }

    pub fn luau(&self) -> String {
        let (fs, fy) = self.floor();
        let d = self.dims();
        let mut s = luau_prelude(
            &format!(
                "a {:?} ({} × {} × {}) dropped flat from {} above the floor",
                self.shape, d[0], d[1], d[2], self.height
            ),
            &format!("{self:?}"),
            &plane_opts(&self.setting, ""),
            self.setting.tick_rate,
        );
        let y0 = self.rest() + self.height;
        let rz = if self.shape == DropShape::Capsule {
            "math.pi / 2"
        } else {
            "0"
        };
        let part = match self.shape {
            DropShape::Pyramid => {
                let (v, t) = Self::pyramid(d);
                let vs: Vec<String> = v.iter().map(|p| lv(*p)).collect();
                let ts: Vec<String> = t
                    .iter()
                    .map(|t| format!("{{ {}, {}, {} }}", t[0] + 1, t[1] + 1, t[2] + 1))
                    .collect();
                format!(
                    "Renderable.MeshPart({{ {} }}, {{ {} }})",
                    vs.join(", "),
                    ts.join(", ")
                )
            }
            other => {
                let name = match other {
                    DropShape::Cube => "Cube",
                    DropShape::Sphere => "Sphere",
                    DropShape::Cylinder => "Cylinder",
                    DropShape::Capsule => "Capsule",
                    _ => "Wedge",
                };
                format!(
                    "(function() local p = Renderable.BasePart(\"{name}\"); p.Size = Vector.new({}, {}, {}); return p end)()",
                    d[0], d[1], d[2]
                )
            }
        };
        let up = if self.shape == DropShape::Capsule {
            "RightVector"
        } else {
            "UpVector"
        };
        s += &format!(
            r#"basic("Cube", Vector.new({fx}, {fyy}, {fz}), CFrame.new(0, {fy}, 0), {{ {{ "Anchored", true }} }})
local body = add({part}, CFrame.new(0, {y0}, 0, 0, 0, {rz}), {{ {{ "HitBoxQuality", {q} }} }})
local nonFinite = 0
for _ = 1, {ticks} do
	world:Step(DT)
	if not finite(body) then
		nonFinite += 1
	end
end
local cf = body.CFrame
local p = cf.Position
print(string.format("ends at (%.4f, %.4f, %.4f), rest height %.4f", p.X, p.Y, p.Z, {rest}))
check("non-finite ticks", nonFinite, 0)
check("tilt (degrees)", math.deg(math.acos(math.clamp(cf.{up}.Y, -1, 1))), 2)
check("sideways drift", math.sqrt(p.X * p.X + p.Z * p.Z), {ts})
check("rest height error", math.abs(p.Y - {rest}), {th})
"#,
            fx = fs[0],
            fyy = fs[1],
            fz = fs[2],
            q = self.setting.quality,
            ticks = self.ticks(),
            rest = self.rest(),
            ts = self.tol_side(),
            th = self.tol_height(),
        );
        s + LUAU_END
    }
}
