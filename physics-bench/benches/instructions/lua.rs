//! What a Luau script pays per part: the first `part.CFrame` read after a tick, a repeated
//! read in the same frame, and a property write (`obj.Velocity`), through lua-client against
//! a real daemon (started by the setup, outside what is counted; Valgrind does not follow
//! it), on a manual plane the setup steps. The collector is stopped while counting (its
//! steps fall where the heap's history puts them), so the counts leave out collecting the
//! values a read makes.

use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use client_sdk::Client;
use gungraun::{library_benchmark, library_benchmark_group};
use mlua::{Function, Lua};

/// The script: a manual plane of `N` parts in free fall, stepped once; `reads` reads every
/// part's CFrame, `writes` sets every object's Velocity.
const SCRIPT: &str = r#"
local PhysicsService = import("PhysicsService")
local Renderable = import("Renderable")
local Primitives = import("Primitives")
local Vector, CFrame = Primitives.Vector, Primitives.CFrame
local world = PhysicsService.New({ TickRate = 0 })
local parts, objects = table.create(N), table.create(N)
for i = 1, N do
	local part = Renderable.BasePart("Cube")
	part.CFrame = CFrame.new(Vector.new((i % 32) * 2, 100 + (i // 32) * 2, 0))
	objects[i] = world:Add(part)
	parts[i] = part
end
world:Step(1 / 60)
step = function()
	world:Step(1 / 60)
end
reads = function()
	for i = 1, N do
		local _ = parts[i].CFrame
	end
end
local v = Vector.new(1, 2, 3)
writes = function()
	for i = 1, N do
		objects[i].Velocity = v
	end
end
"#;

/// A daemon of a domain of its own, a Lua state connected to it running [`SCRIPT`], and the
/// function to count. The daemon is stopped when this is dropped.
pub struct Script {
    _lua: Lua,
    _host: lua_client::Host,
    measured: Function,
    daemon: Child,
    domain: String,
}

impl Drop for Script {
    fn drop(&mut self) {
        let _ = self.daemon.kill();
        let _ = self.daemon.wait();
        let _ = physics_daemon::cleanup_domain(&self.domain);
    }
}

/// The `physics-daemon` built beside this benchmark (target/PROFILE/).
fn daemon_binary() -> PathBuf {
    let exe = std::env::current_exe().expect("current exe");
    let profile_dir = exe
        .parent()
        .and_then(|deps| deps.parent())
        .expect("target/PROFILE");
    let daemon = profile_dir.join("physics-daemon");
    assert!(
        daemon.is_file(),
        "{} not found: build it first (cargo build --workspace --bins)",
        daemon.display()
    );
    daemon
}

/// In a warm-up list: a frame of the host (it picks up the newest tick's sample and sends
/// the frame's writes), as `physics-lua` runs one between two frames of a script.
const FRAME: &str = "(frame)";

/// [`SCRIPT`] with `n` parts; `measured` names the global function counted; `warm` runs
/// before it is counted (after the setup's tick).
fn script(n: usize, measured: &str, warm: &[&str]) -> Script {
    let domain = format!("counts-lua-{}", std::process::id());
    let daemon = Command::new(daemon_binary())
        .args(["--domain", &domain])
        .env("PHYSICS_LOG", "warn")
        .stdout(Stdio::null())
        .spawn()
        .expect("start physics-daemon");
    let deadline = Instant::now() + Duration::from_secs(60);
    let client = loop {
        match Client::connect(&domain) {
            Ok(client) => break client,
            Err(e) if Instant::now() > deadline => panic!("no daemon on {domain}: {e}"),
            Err(_) => std::thread::sleep(Duration::from_millis(50)),
        }
    };
    let lua = Lua::new();
    let host = lua_client::install(&lua, client).expect("install the API");
    lua.globals().set("N", n).expect("N");
    lua.load(SCRIPT).exec().expect("the script runs");
    let globals = lua.globals();
    for name in warm {
        if *name == FRAME {
            host.frame(1.0 / 60.0).expect("a frame");
            continue;
        }
        let f: Function = globals.get(*name).expect("a warm-up function");
        f.call::<()>(()).expect("warm-up");
    }
    let measured = globals.get(measured).expect("the measured function");
    // The collector's steps depend on the heap's history (addresses, the daemon's pid in
    // names): a full collection now and none while counting keep the count to the reads.
    lua.gc_collect().expect("a full collection");
    lua.gc_stop();
    Script {
        _lua: lua,
        _host: host,
        measured,
        daemon,
        domain,
    }
}

/// The first read of every part after a tick (and the frame that picks it up).
fn after_tick(n: usize) -> Script {
    script(n, "reads", &["reads", "step", FRAME])
}

/// A second read of every part in the same frame.
fn read_again(n: usize) -> Script {
    script(n, "reads", &["step", FRAME, "reads"])
}

/// A Velocity write to every object.
fn velocity(n: usize) -> Script {
    script(n, "writes", &["step", FRAME])
}

#[library_benchmark]
#[bench::n100(args = (100), setup = after_tick)]
#[bench::n1000(args = (1000), setup = after_tick)]
fn first_cframe_read(s: Script) -> Script {
    s.measured.call::<()>(()).expect("reads");
    s
}

#[library_benchmark]
#[bench::n100(args = (100), setup = read_again)]
#[bench::n1000(args = (1000), setup = read_again)]
fn repeated_cframe_read(s: Script) -> Script {
    s.measured.call::<()>(()).expect("reads");
    s
}

#[library_benchmark]
#[bench::n100(args = (100), setup = velocity)]
#[bench::n1000(args = (1000), setup = velocity)]
fn velocity_write(s: Script) -> Script {
    s.measured.call::<()>(()).expect("writes");
    s
}

library_benchmark_group!(
    name = lua_group;
    benchmarks = first_cframe_read, repeated_cframe_read, velocity_write
);
