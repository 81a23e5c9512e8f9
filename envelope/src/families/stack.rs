//! Stacks and columns: `count` equal cubes of side `size` stacked on an anchored floor, the
//! weights set by `order` from 1 and `ratio` (heavy on top: every box 1 but the top one;
//! heavy at the bottom: the bottom one `ratio`; alternating: 1, ratio, 1, ratio, … the
//! issue's column). Default gravity and damping; stepped for [`SETTLE_S`].
//!
//! Oracles after [`SETTLE_S`] (tolerance `tol = 0.05 + 0.01 · size`, i.e. 5 hundredths of a
//! unit plus 1 % of a side): every box's centre within `tol` of its exact resting height
//! (`size/2 + i · size`: resting bodies touch) (`rest height`) and of its starting column
//! (`in place`); tilted at most 2° (`upright`); every box asleep (`sleeps`); the plane's
//! deepest contact at most `tol` (`penetration`).

use shm_layout::{ObjectProp, Pose, Shape};

use super::{draw_setting, plane_opts, tilt_deg};
use crate::luau::{luau_prelude, LUAU_END};
use crate::oracle::{at_most, finish, Outcome};
use crate::plane::{BuildResult, Run};
use crate::rng::{Rng, Span};
use crate::setting::{Setting, SettingRanges};
use crate::steps::{toward, toward_int};

/// The ranges a stack case is drawn from (their values: [`crate::space`]).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct StackRanges {
    pub setting: SettingRanges,
    pub count: (u32, u32),
    pub ratio: Span,
    pub size: Span,
    pub orders: &'static [Order],
}

/// Simulated seconds before the stack is judged.
pub const SETTLE_S: f32 = 5.0;

/// How the weights are laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Order {
    HeavyTop,
    HeavyBottom,
    Alternating,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Stack {
    pub setting: Setting,
    pub count: u32,
    pub ratio: f64,
    pub size: f64,
    pub order: Order,
}

impl Stack {
    pub fn draw(rng: &mut Rng, r: &StackRanges) -> Stack {
        Stack {
            setting: draw_setting(rng, &r.setting),
            count: rng.int(r.count.0, r.count.1),
            ratio: rng.log_uniform(r.ratio),
            size: rng.log_uniform(r.size),
            order: rng.pick(r.orders),
        }
    }

    pub fn tol(&self) -> f64 {
        0.05 + 0.01 * self.size
    }

    pub fn weights(&self) -> Vec<f64> {
        let n = self.count as usize;
        (0..n)
            .map(|i| match self.order {
                Order::HeavyTop if i + 1 == n => self.ratio,
                Order::HeavyBottom if i == 0 => self.ratio,
                Order::Alternating if i % 2 == 1 => self.ratio,
                _ => 1.0,
            })
            .collect()
    }

    fn floor(&self) -> ([f64; 3], f64) {
        let side = (20.0 * self.size).max(200.0);
        let thick = self.size.max(1.0);
        ([side, thick, side], -thick / 2.0)
    }

    fn rest(&self, i: usize) -> f64 {
        self.size / 2.0 + i as f64 * self.size
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
        let s = self.size as f32;
        let mut boxes = Vec::new();
        for (i, w) in self.weights().into_iter().enumerate() {
            boxes.push(run.add(
                Shape::Cube { size: [s; 3] },
                Pose::at([0.0, self.rest(i) as f32, 0.0]),
                &[
                    ObjectProp::HitBoxQuality(self.setting.quality),
                    ObjectProp::Weight(w as f32),
                ],
            )?);
        }
        for _ in 0..run.ticks_for(SETTLE_S) {
            run.step()?;
        }
        let (mut dy, mut dxz, mut tilt, mut awake) = (0.0f64, 0.0f64, 0.0f64, 0usize);
        for (i, b) in boxes.iter().enumerate() {
            let st = run.state(*b);
            let p = st.position.map(|v| v as f64);
            dy = dy.max((p[1] - self.rest(i)).abs());
            dxz = dxz.max((p[0] * p[0] + p[2] * p[2]).sqrt());
            tilt = tilt.max(tilt_deg(st.rotation, [0.0, 1.0, 0.0]));
            awake += usize::from(!st.is_sleeping());
        }
        let tol = self.tol();
        let mut v = Vec::new();
        at_most(&mut v, "rest height", dy, tol);
        at_most(&mut v, "in place", dxz, tol);
        at_most(&mut v, "upright", tilt, 2.0);
        at_most(&mut v, "sleeps", awake as f64, 0.0);
        at_most(
            &mut v,
            "penetration",
            run.plane.header().max_penetration as f64,
            tol,
        );
        Ok(finish(&run, v))
    }

    pub fn simpler(&self) -> Vec<Stack> {
        let mut out = Vec::new();
        for s in self.setting.simpler() {
            out.push(Stack {
                setting: s,
                ..self.clone()
            });
        }
        for c in toward_int(self.count, 2) {
            out.push(Stack {
                count: c,
                ..self.clone()
            });
        }
        if self.order != Order::HeavyTop {
            out.push(Stack {
                order: Order::HeavyTop,
                ..self.clone()
            });
        }
        for r in toward(self.ratio, 1.0) {
            out.push(Stack {
                ratio: r,
                ..self.clone()
            });
        }
        for s in toward(self.size, 1.0) {
            out.push(Stack {
                size: s,
                ..self.clone()
            });
        }
        out
    }

    pub fn luau(&self) -> String {
        let (fs, fy) = self.floor();
        let weights: Vec<String> = self.weights().iter().map(|w| w.to_string()).collect();
        let mut s = luau_prelude(
            &format!(
                "a stack of {} cubes of side {} ({:?}, mass ratio {})",
                self.count, self.size, self.order, self.ratio
            ),
            &format!("{self:?}"),
            &plane_opts(&self.setting, ""),
            self.setting.tick_rate,
        );
        s += &format!(
            r#"local S, Q, TOL = {size}, {q}, {tol}
basic("Cube", Vector.new({fx}, {fy_}, {fz}), CFrame.new(0, {fy}, 0), {{ {{ "Anchored", true }} }})
local weights = {{ {weights} }}
local boxes = {{}}
for i, w in weights do
	boxes[i] = basic("Cube", Vector.new(S, S, S), CFrame.new(0, S / 2 + (i - 1) * S, 0), {{ {{ "HitBoxQuality", Q }}, {{ "Weight", w }} }})
end
local nonFinite = 0
for _ = 1, {ticks} do
	world:Step(DT)
	for _, o in boxes do
		if not finite(o) then
			nonFinite += 1
		end
	end
end
local dy, dxz, tilt, awake = 0, 0, 0, 0
for i, o in boxes do
	local p = o.CFrame.Position
	print(string.format("box %d (weight %g): y %.4f (rest %.4f), x %.4f, z %.4f, sleeping %s", i, weights[i], p.Y, S / 2 + (i - 1) * S, p.X, p.Z, tostring(o.Sleeping)))
	dy = math.max(dy, math.abs(p.Y - (S / 2 + (i - 1) * S)))
	dxz = math.max(dxz, math.sqrt(p.X * p.X + p.Z * p.Z))
	tilt = math.max(tilt, math.deg(math.acos(math.clamp(o.CFrame.UpVector.Y, -1, 1))))
	awake += if o.Sleeping then 0 else 1
end
check("non-finite body-ticks", nonFinite, 0)
check("rest height error", dy, TOL)
check("in place (horizontal drift)", dxz, TOL)
check("tilt (degrees)", tilt, 2)
check("boxes awake", awake, 0)
"#,
            size = self.size,
            q = self.setting.quality,
            tol = self.tol(),
            fx = fs[0],
            fy_ = fs[1],
            fz = fs[2],
            weights = weights.join(", "),
            ticks = (SETTLE_S * self.setting.tick_rate).round() as u64,
        );
        s + LUAU_END
    }
}
