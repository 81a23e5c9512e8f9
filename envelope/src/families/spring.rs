//! Springs: a ball (radius 0.25, weight `mass`) on an undamped spring of `stiffness` in zero
//! gravity without damping, released at rest `amplitude` from its rest position along x:
//! a `Spring` joint to the world (rest length 2) or a SixDof joint with X free and an axis
//! spring (Damping 0) on X. Stepped at the case's tick rate for max(10 s, 3 periods).
//!
//! Energy is `½ m v² + ½ k s²` (s: stretch), averaged over whole periods of the exact
//! period `2π √(m/k)` (the per-tick value of a discrete integrator oscillates within a
//! period; its period average does not). Oracles: the last period's average keeps at least
//! 99 % of the first period's (`energy kept`), and no period's average exceeds the first's
//! by more than 1 % (`no energy gain`).

use shm_layout::{AxisMode, AxisMotor, JointKind, JointProp, ObjectProp, PlaneProp, Pose, Shape};

use super::plane_opts;
use crate::luau::{luau_prelude, LUAU_END};
use crate::oracle::{at_least, at_most, finish, Outcome};
use crate::plane::{BuildResult, Run};
use crate::rng::{Rng, Span};
use crate::setting::{Setting, SettingRanges};
use crate::steps::toward;

/// The ranges a spring case is drawn from (their values: [`crate::space`]).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct SpringRanges {
    pub setting: SettingRanges,
    pub kinds: &'static [SpringKind],
    pub stiffness: Span,
    pub mass: Span,
    pub amplitude: Span,
}

/// Rest length of a `Spring` joint.
const REST: f64 = 2.0;

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum SpringKind {
    Spring,
    AxisSpring,
}

#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Spring {
    /// Tick rate and iterations (quality: the ball's).
    pub setting: Setting,
    pub kind: SpringKind,
    pub stiffness: f64,
    pub mass: f64,
    pub amplitude: f64,
}

impl Spring {
    pub fn draw(rng: &mut Rng, r: &SpringRanges) -> Spring {
        Spring {
            setting: super::draw_setting(rng, &r.setting),
            kind: rng.pick(r.kinds),
            stiffness: rng.log_uniform(r.stiffness),
            mass: rng.log_uniform(r.mass),
            amplitude: rng.log_uniform(r.amplitude),
        }
    }

    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI * (self.mass / self.stiffness).sqrt()
    }

    fn duration(&self) -> f64 {
        (3.0 * self.period()).max(10.0)
    }

    /// The ball's x at rest, and where it starts.
    fn rest_and_start(&self) -> (f64, f64) {
        match self.kind {
            SpringKind::Spring => (REST, REST + self.amplitude),
            SpringKind::AxisSpring => (0.0, self.amplitude),
        }
    }

    pub fn run(&self) -> BuildResult<Outcome> {
        let (run, kept, gain) = self.measure()?;
        let mut v = Vec::new();
        at_least(&mut v, "energy kept", kept, 0.99);
        at_most(&mut v, "no energy gain", gain, 1.01);
        Ok(finish(&run, v))
    }

    /// Runs the case: the last period's average energy over the first's, and the worst
    /// period's over the first's.
    pub fn measure(&self) -> BuildResult<(Run, f64, f64)> {
        let mut run = Run::new(
            &self.setting,
            &[
                PlaneProp::Gravity([0.0; 3]),
                PlaneProp::LinearDamping(0.0),
                PlaneProp::AngularDamping(0.0),
            ],
        )?;
        let (rest, x0) = self.rest_and_start();
        let ball = run.add(
            Shape::Sphere { radius: 0.25 },
            Pose::at([x0 as f32, 5.0, 0.0]),
            &[
                ObjectProp::HitBoxQuality(self.setting.quality),
                ObjectProp::Weight(self.mass as f32),
            ],
        )?;
        let k = self.stiffness as f32;
        match self.kind {
            SpringKind::Spring => run.joint(
                JointKind::Spring,
                ball,
                None,
                vec![
                    JointProp::AnchorA([0.0; 3]),
                    JointProp::AnchorB([0.0, 5.0, 0.0]),
                    JointProp::RestLength(REST as f32),
                    JointProp::Stiffness(k),
                    JointProp::Damping(0.0),
                ],
            )?,
            SpringKind::AxisSpring => {
                let mut axes = [AxisMode::Locked; 6];
                axes[0] = AxisMode::Free;
                run.joint(
                    JointKind::SixDof,
                    ball,
                    None,
                    vec![
                        JointProp::AnchorA([0.0; 3]),
                        JointProp::AnchorB([0.0, 5.0, 0.0]),
                        JointProp::Axes(axes),
                        JointProp::AxisMotor {
                            axis: 0,
                            motor: Some(AxisMotor::spring(k, 0.0, 0.0)),
                        },
                    ],
                )?
            }
        };
        let (m, kk) = (self.mass, self.stiffness);
        let ticks = run.ticks_for(self.duration() as f32);
        let per = ((self.period() / run.dt as f64).round() as usize).max(1);
        let mut energy = Vec::with_capacity(ticks as usize);
        for _ in 0..ticks {
            run.step()?;
            let b = run.state(ball);
            let p = b.position.map(|c| c as f64);
            let v = b.linear_velocity.map(|c| c as f64);
            let stretch = match self.kind {
                SpringKind::Spring => {
                    (p[0] * p[0] + (p[1] - 5.0).powi(2) + p[2] * p[2]).sqrt() - rest
                }
                SpringKind::AxisSpring => p[0] - rest,
            };
            energy.push(
                0.5 * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 0.5 * kk * stretch * stretch,
            );
        }
        let averages: Vec<f64> = energy
            .chunks_exact(per)
            .map(|c| c.iter().sum::<f64>() / c.len() as f64)
            .collect();
        let (first, last) = match (averages.first(), averages.last()) {
            (Some(f), Some(l)) => (*f, *l),
            _ => return Err("no whole period was run".into()),
        };
        let worst = averages
            .iter()
            .fold(0.0f64, |a, &b| if b.is_nan() { f64::NAN } else { a.max(b) });
        Ok((run, last / first, worst / first))
    }

    pub fn simpler(&self) -> Vec<Spring> {
        let mut out = Vec::new();
        for s in self.setting.simpler() {
            out.push(Spring {
                setting: s,
                ..self.clone()
            });
        }
        if self.kind != SpringKind::AxisSpring {
            out.push(Spring {
                kind: SpringKind::AxisSpring,
                ..self.clone()
            });
        }
        for k in toward(self.stiffness, 10.0) {
            out.push(Spring {
                stiffness: k,
                ..self.clone()
            });
        }
        for m in toward(self.mass, 1.0) {
            out.push(Spring {
                mass: m,
                ..self.clone()
            });
        }
        for a in toward(self.amplitude, 0.5) {
            out.push(Spring {
                amplitude: a,
                ..self.clone()
            });
        }
        out
    }

    pub fn luau(&self) -> String {
        let (rest, x0) = self.rest_and_start();
        let mut s = luau_prelude(
            &format!(
                "an undamped {:?} (k {}, m {}) released {} from rest",
                self.kind, self.stiffness, self.mass, self.amplitude
            ),
            &format!("{self:?}"),
            &plane_opts(
                &self.setting,
                ", Gravity = Vector.new(0, 0, 0), LinearDamping = 0, AngularDamping = 0",
            ),
            self.setting.tick_rate,
        );
        let joint = match self.kind {
            SpringKind::Spring => format!(
                "world:NewJoint(\"Spring\", ball, nil, {{ AnchorA = Vector.new(0, 0, 0), AnchorB = Vector.new(0, 5, 0), RestLength = {REST}, Stiffness = K, Damping = 0 }})"
            ),
            SpringKind::AxisSpring => "world:NewJoint(\"SixDof\", ball, nil, { AnchorA = Vector.new(0, 0, 0), AnchorB = Vector.new(0, 5, 0), Axes = { X = \"Free\" } }):SetAxisSpring(\"X\", K, 0, 0)".to_string(),
        };
        let stretch = match self.kind {
            SpringKind::Spring => "(p - Vector.new(0, 5, 0)).Magnitude - REST",
            SpringKind::AxisSpring => "p.X - REST",
        };
        s += &format!(
            r#"local K, M, REST = {k}, {m}, {rest}
local ball = basic("Sphere", Vector.new(0.5, 0.5, 0.5), CFrame.new({x0}, 5, 0), {{ {{ "HitBoxQuality", {q} }}, {{ "Weight", M }} }})
{joint}
local PER = math.max(1, math.floor(2 * math.pi * math.sqrt(M / K) / DT + 0.5))
local sums, acc, n, nonFinite = {{}}, 0, 0, 0
for _ = 1, {ticks} do
	world:Step(DT)
	local p, v = ball.CFrame.Position, ball.Velocity
	local s = {stretch}
	acc += 0.5 * M * (v.X * v.X + v.Y * v.Y + v.Z * v.Z) + 0.5 * K * s * s
	n += 1
	if n == PER then
		table.insert(sums, acc / PER)
		acc, n = 0, 0
	end
	if not finite(ball) then
		nonFinite += 1
	end
end
local worst = 0
for i, e in sums do
	worst = math.max(worst, e)
end
print(string.format("period-averaged energy: first %.6g, last %.6g (initial ½kA² = %.6g) over %d periods", sums[1], sums[#sums], 0.5 * K * {a} * {a}, #sums))
check("non-finite ticks", nonFinite, 0)
check("energy kept (last / first period)", sums[#sums] / sums[1], 0.99, true)
check("energy gain (worst / first period)", worst / sums[1], 1.01)
"#,
            k = self.stiffness,
            m = self.mass,
            rest = rest,
            x0 = x0,
            q = self.setting.quality,
            ticks = (self.duration() * self.setting.tick_rate as f64).round() as u64,
            a = self.amplitude,
        );
        s + LUAU_END
    }
}
