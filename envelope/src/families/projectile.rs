//! Projectiles: a ball of `radius` (weight 1, the setting's HitBoxQuality) launched at
//! `speed` toward the centre of a `thickness` × H × H box, at `angle` degrees off its
//! normal (+x), in zero gravity without damping. The target is an anchored wall (H = max(20,
//! 40 · radius)) or a free body (H = max(2, 8 · radius), weight `mass_ratio`, HitBoxQuality
//! `target_quality`). The ball starts 2.5 ticks of travel (plus a unit) from the face and
//! the run lasts twice its flight to the target's centre plus 0.5 s.
//!
//! Oracles: the swept check (`passes through`): between every two ticks the ball's centre,
//! in the target's frame, must not cross the target's mid-plane within its face's extent
//! (where the centre would be inside the target), nor end there past it; the ball and target end with at most 1 % more kinetic energy than the ball
//! brought (`no energy gain`); against a free body, the total momentum changes by at most
//! 1 % of the ball's (`momentum`).

use shm_layout::{ObjectProp, PlaneProp, Pose, Shape};

use super::{draw_setting, plane_opts};
use crate::luau::{luau_prelude, lv, LUAU_END};
use crate::oracle::{at_most, finish, Outcome};
use crate::plane::{norm, sub, unrotate, BuildResult, Run};
use crate::rng::{Rng, Span};
use crate::setting::{Setting, SettingRanges};
use crate::steps::toward;

/// The ranges a projectile case is drawn from (their values: [`crate::space`]).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct ProjectileRanges {
    /// The ball's quality is `setting.quality`.
    pub setting: SettingRanges,
    pub targets: &'static [Target],
    pub speed: Span,
    pub radius: Span,
    pub thickness: Span,
    pub target_quality: (u32, u32),
    /// Degrees off the target's normal, uniform.
    pub angle: Span,
    /// Target weight / ball weight (free bodies).
    pub mass_ratio: Span,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Target {
    Wall,
    Body,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Projectile {
    /// Tick rate, iterations and the ball's HitBoxQuality.
    pub setting: Setting,
    pub target: Target,
    pub speed: f64,
    pub radius: f64,
    pub thickness: f64,
    pub target_quality: u32,
    pub angle: f64,
    pub mass_ratio: f64,
}

impl Projectile {
    pub fn draw(rng: &mut Rng, r: &ProjectileRanges) -> Projectile {
        Projectile {
            setting: draw_setting(rng, &r.setting),
            target: rng.pick(r.targets),
            speed: rng.log_uniform(r.speed),
            radius: rng.log_uniform(r.radius),
            thickness: rng.log_uniform(r.thickness),
            target_quality: rng.int_log(r.target_quality.0, r.target_quality.1),
            angle: rng.uniform(r.angle).round(),
            mass_ratio: rng.log_uniform(r.mass_ratio),
        }
    }

    fn extent(&self) -> f64 {
        match self.target {
            Target::Wall => (40.0 * self.radius).max(20.0),
            Target::Body => (8.0 * self.radius).max(2.0),
        }
    }

    fn dir(&self) -> [f64; 3] {
        let a = self.angle.to_radians();
        [a.cos(), a.sin(), 0.0]
    }

    /// The ball's start (the target's centre is the origin) and the ticks run.
    fn start_and_ticks(&self) -> ([f64; 3], u64) {
        let dt = 1.0 / self.setting.tick_rate as f64;
        let d = (self.thickness / 2.0 + self.radius + 1.0 + 2.5 * self.speed * dt)
            / self.angle.to_radians().cos();
        let dir = self.dir();
        let ticks = ((2.0 * d / self.speed + 0.5) / dt).ceil() as u64;
        (dir.map(|c| -c * d), ticks)
    }

    fn target_weight(&self) -> f64 {
        self.mass_ratio
    }

    pub fn run(&self) -> BuildResult<Outcome> {
        let mut run = Run::new(
            &self.setting,
            &[
                PlaneProp::Gravity([0.0; 3]),
                PlaneProp::LinearDamping(0.0),
                PlaneProp::AngularDamping(0.0),
            ],
        )?;
        let (h, t, r) = (
            self.extent() as f32,
            self.thickness as f32,
            self.radius as f32,
        );
        let target_size = [t, h, h];
        let mut tprops = vec![ObjectProp::HitBoxQuality(self.target_quality)];
        match self.target {
            Target::Wall => tprops.push(ObjectProp::Anchored(true)),
            Target::Body => tprops.push(ObjectProp::Weight(self.target_weight() as f32)),
        }
        let target = run.add(
            Shape::Cube { size: target_size },
            Pose::at([0.0; 3]),
            &tprops,
        )?;
        let (start, ticks) = self.start_and_ticks();
        let v0 = self.dir().map(|c| (c * self.speed) as f32);
        let ball = run.add(
            Shape::Sphere { radius: r },
            Pose::at(start.map(|v| v as f32)),
            &[
                ObjectProp::HitBoxQuality(self.setting.quality),
                ObjectProp::Weight(1.0),
                ObjectProp::Velocity(v0),
            ],
        )?;
        let rel = |run: &Run| {
            let (b, tg) = (run.state(ball), run.state(target));
            unrotate(tg.rotation, sub(b.position, tg.position).map(|v| v as f32))
        };
        // The ball's centre inside the face's extent at the mid-plane: inside the target.
        let half = h as f64 / 2.0;
        let mut crossings = 0usize;
        let mut prev = rel(&run);
        for _ in 0..ticks {
            run.step()?;
            let now = rel(&run);
            if prev[0] < 0.0 && now[0] >= 0.0 {
                let s = -prev[0] / (now[0] - prev[0]);
                let y = prev[1] + s * (now[1] - prev[1]);
                let z = prev[2] + s * (now[2] - prev[2]);
                if y.abs() <= half && z.abs() <= half {
                    crossings += 1;
                }
            }
            prev = now;
        }
        if prev[0] >= 0.0 && prev[1].abs() <= half && prev[2].abs() <= half {
            crossings = crossings.max(1);
        }
        let mut v = Vec::new();
        at_most(&mut v, "passes through", crossings as f64, 0.0);
        // Energies and momenta (weights: ball 1, body mass_ratio).
        let ke0 = 0.5 * self.speed * self.speed;
        let b = run.state(ball);
        let inertia_ball = 0.4 * self.radius * self.radius;
        let mut ke = 0.5 * norm(b.linear_velocity.map(|c| c as f64)).powi(2)
            + 0.5 * inertia_ball * norm(b.angular_velocity.map(|c| c as f64)).powi(2);
        let mut p = b.linear_velocity.map(|c| c as f64);
        if self.target == Target::Body {
            let m = self.target_weight();
            let tg = run.state(target);
            let w = unrotate(tg.rotation, tg.angular_velocity);
            let (a, bb, c) = (t as f64, h as f64, h as f64);
            let inertia = [
                m / 12.0 * (bb * bb + c * c),
                m / 12.0 * (a * a + c * c),
                m / 12.0 * (a * a + bb * bb),
            ];
            let vt = tg.linear_velocity.map(|c| c as f64);
            ke += 0.5 * m * norm(vt).powi(2)
                + 0.5 * (0..3).map(|i| inertia[i] * w[i] * w[i]).sum::<f64>();
            for i in 0..3 {
                p[i] += m * vt[i];
            }
            let p0 = self.dir().map(|c| c * self.speed);
            let dp = norm([p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]]);
            at_most(&mut v, "momentum", dp / self.speed, 0.01);
        }
        at_most(&mut v, "no energy gain", ke / ke0, 1.01);
        Ok(finish(&run, v))
    }

    pub fn simpler(&self) -> Vec<Projectile> {
        let mut out = Vec::new();
        for s in self.setting.simpler() {
            out.push(Projectile {
                setting: s,
                ..self.clone()
            });
        }
        if self.target_quality != 1 {
            out.push(Projectile {
                target_quality: 1,
                ..self.clone()
            });
            if self.target_quality > 2 {
                out.push(Projectile {
                    target_quality: self.target_quality / 2,
                    ..self.clone()
                });
            }
        }
        if self.angle != 0.0 {
            out.push(Projectile {
                angle: 0.0,
                ..self.clone()
            });
        }
        for s in toward(self.speed, 100.0) {
            out.push(Projectile {
                speed: s,
                ..self.clone()
            });
        }
        for t in toward(self.thickness, 1.0) {
            out.push(Projectile {
                thickness: t,
                ..self.clone()
            });
        }
        for r in toward(self.radius, 0.5) {
            out.push(Projectile {
                radius: r,
                ..self.clone()
            });
        }
        for m in toward(self.mass_ratio, 1.0) {
            out.push(Projectile {
                mass_ratio: m,
                ..self.clone()
            });
        }
        out
    }

    pub fn luau(&self) -> String {
        let (start, ticks) = self.start_and_ticks();
        let h = self.extent();
        let v0 = self.dir().map(|c| c * self.speed);
        let mut s = luau_prelude(
            &format!(
                "a ball of radius {} (q{}) at {} u/s, {}° off the normal, at a {} {} thick (q{})",
                self.radius,
                self.setting.quality,
                self.speed,
                self.angle,
                match self.target {
                    Target::Wall => "anchored wall",
                    Target::Body => "free body",
                },
                self.thickness,
                self.target_quality
            ),
            &format!("{self:?}"),
            &plane_opts(
                &self.setting,
                ", Gravity = Vector.new(0, 0, 0), LinearDamping = 0, AngularDamping = 0",
            ),
            self.setting.tick_rate,
        );
        let target_props = match self.target {
            Target::Wall => "{ \"Anchored\", true }".to_string(),
            Target::Body => format!("{{ \"Weight\", {} }}", self.target_weight()),
        };
        s += &format!(
            r#"local HALF = {half}
local target = basic("Cube", Vector.new({t}, {h}, {h}), CFrame.new(0, 0, 0), {{ {{ "HitBoxQuality", {qt} }}, {tp} }})
local start = {start}
local ball = basic("Sphere", Vector.new({d}, {d}, {d}), CFrame.new(start.X, start.Y, start.Z), {{ {{ "HitBoxQuality", {qb} }}, {{ "Weight", 1 }}, {{ "Velocity", {v0} }} }})
local function rel(): any
	return target.CFrame:PointToObjectSpace(ball.CFrame.Position)
end
local crossings, nonFinite = 0, 0
local prev = rel()
for tick = 1, {ticks} do
	world:Step(DT)
	local now = rel()
	if prev.X < 0 and now.X >= 0 then
		local s = -prev.X / (now.X - prev.X)
		local y, z = prev.Y + s * (now.Y - prev.Y), prev.Z + s * (now.Z - prev.Z)
		if math.abs(y) <= HALF and math.abs(z) <= HALF then
			crossings += 1
			print(string.format("tick %d: the ball crossed the target's mid-plane (x %.3f -> %.3f in its frame)", tick, prev.X, now.X))
		end
	end
	prev = now
	if not finite(ball) or not finite(target) then
		nonFinite += 1
	end
end
local p, v = ball.CFrame.Position, ball.Velocity
print(string.format("ball ends at (%.3f, %.3f, %.3f), velocity (%.1f, %.1f, %.1f)", p.X, p.Y, p.Z, v.X, v.Y, v.Z))
check("non-finite ticks", nonFinite, 0)
check("crossings through the target", crossings, 0)
"#,
            half = h / 2.0,
            t = self.thickness,
            h = h,
            qt = self.target_quality,
            tp = target_props,
            start = lv(start),
            d = 2.0 * self.radius,
            qb = self.setting.quality,
            v0 = lv(v0),
            ticks = ticks,
        );
        s + LUAU_END
    }
}
