//! The pieces every Luau repro shares: its opening ([`luau_prelude`]), its closing
//! ([`LUAU_END`]) and vectors ([`lv`]).

/// The opening of every repro: imports, the plane, a part helper that applies properties
/// in order, the step length.
pub fn luau_prelude(title: &str, case: &str, plane: &str, tick_rate: f32) -> String {
    format!(
        r#"-- physics-bench envelope repro: {title}
-- case: {case}
-- run: physics-lua THIS_FILE
local PhysicsService = import("PhysicsService")
local Renderable = import("Renderable")
local Vector = import("Primitives").Vector
local CFrame = import("Primitives").CFrame

local world = PhysicsService.New({{ TickRate = 0, {plane} }})
local DT = 1 / {tick_rate}
local failed = false
local function check(what: string, figure: number, bound: number, atLeast: boolean?)
	local bad = figure ~= figure or (if atLeast then figure < bound else figure > bound)
	print(string.format("%s: %.6g (%s %.6g) %s", what, figure, if atLeast then ">=" else "<=", bound, if bad then "FAIL" else "ok"))
	failed = failed or bad
end
local function add(part: any, cf: any, props: {{ {{ any }} }}): any
	part.CFrame = cf
	local o: any = world:Add(part)
	for _, kv in props do
		o[kv[1]] = kv[2]
	end
	return o
end
local function basic(shape: string, size: any, cf: any, props: {{ {{ any }} }}): any
	local p = Renderable.BasePart(shape)
	p.Size = size
	return add(p, cf, props)
end
local function finite(o: any): boolean
	local p, v = o.CFrame.Position, o.Velocity
	return p.X == p.X and p.Y == p.Y and p.Z == p.Z and v.X == v.X and v.Y == v.Y and v.Z == v.Z
		and math.abs(p.X) < math.huge and math.abs(p.Y) < math.huge and math.abs(p.Z) < math.huge
end
"#
    )
}

/// The closing of every repro: fail the script when a check failed.
pub const LUAU_END: &str = r#"if failed then
	error("envelope repro: an oracle failed (see above)")
end
print("envelope repro: every oracle holds")
"#;

/// A Luau `Vector.new(...)`.
pub fn lv(v: [f64; 3]) -> String {
    format!("Vector.new({}, {}, {})", v[0], v[1], v[2])
}
