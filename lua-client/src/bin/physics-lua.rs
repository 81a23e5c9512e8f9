//! `physics-lua SCRIPT.luau`: runs a Luau script against the physics daemon of a domain
//! (starting one for the run when none answers), then keeps running frames while the script
//! has `Heart` handlers, pending waits or change listeners.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::Parser;
use mlua::{Lua, Value, Variadic};

#[derive(Parser, Debug)]
#[command(version, about = "Run a Luau script against the physics service")]
struct Args {
    /// The Luau script to run.
    script: PathBuf,
    /// Domain of the daemon to use; one is started for the run when none answers.
    #[arg(long, env = "PHYSICS_DOMAIN", default_value = "physics")]
    domain: String,
    /// Stop running frames after this many seconds (default: while there is work).
    #[arg(long)]
    seconds: Option<f64>,
    /// Frames per second.
    #[arg(long, default_value_t = 60.0)]
    fps: f64,
}

/// `print` writes to stdout, one line per call, flushed so output interleaves sensibly.
fn install_print(lua: &Lua) -> mlua::Result<()> {
    let tostring: mlua::Function = lua.globals().get("tostring")?;
    let print = lua.create_function(move |_, args: Variadic<Value>| {
        let mut line = String::new();
        for (i, v) in args.into_iter().enumerate() {
            if i > 0 {
                line.push('\t');
            }
            line.push_str(&tostring.call::<mlua::String>(v)?.to_string_lossy());
        }
        let mut out = std::io::stdout().lock();
        let _ = writeln!(out, "{line}");
        let _ = out.flush();
        Ok(())
    })?;
    lua.globals().set("print", print)
}

fn run(args: &Args, stop: &AtomicBool) -> Result<(), String> {
    if !(args.fps.is_finite() && args.fps > 0.0) {
        return Err(format!("--fps must be a positive number, got {}", args.fps));
    }
    if let Some(s) = args.seconds {
        if !(s.is_finite() && s >= 0.0) {
            return Err(format!("--seconds must be a non-negative number, got {s}"));
        }
    }
    let source = std::fs::read_to_string(&args.script)
        .map_err(|e| format!("cannot read {}: {e}", args.script.display()))?;
    // A daemon started for this run logs warnings only, unless the user asked for more.
    if std::env::var_os("PHYSICS_LOG").is_none() {
        std::env::set_var("PHYSICS_LOG", "warn");
    }
    let session = client_sdk::connect_or_start(&args.domain).map_err(|e| e.to_string())?;
    let lua = Lua::new();
    let lua_err = |e: mlua::Error| e.to_string();
    install_print(&lua).map_err(lua_err)?;
    let host = lua_client::install(&lua, session.client.clone()).map_err(lua_err)?;
    let chunk = lua
        .load(source)
        .set_name(format!("@{}", args.script.display()))
        .into_function()
        .map_err(lua_err)?;
    let started = Instant::now();
    host.spawn(chunk).map_err(lua_err)?;
    host.flush().map_err(lua_err)?;

    let frame = Duration::from_secs_f64(1.0 / args.fps);
    let deadline = args.seconds.map(|s| started + Duration::from_secs_f64(s));
    let mut last = Instant::now();
    while host.busy() && !stop.load(Ordering::Relaxed) {
        let mut next = last + frame;
        // With only waits pending, sleep until the earliest is due rather than spinning frames.
        if host.next_wake_in().is_some() && !host.busy_every_frame() {
            let wake = Instant::now() + Duration::from_secs_f64(host.next_wake_in().unwrap_or(0.0));
            next = next.max(wake);
        }
        if let Some(d) = deadline {
            if next > d {
                break;
            }
        }
        let now = Instant::now();
        if next > now {
            std::thread::sleep(next - now);
        }
        let now = Instant::now();
        let dt = (now - last).as_secs_f64();
        last = now;
        host.frame(dt).map_err(lua_err)?;
    }
    drop(host);
    drop(lua);
    drop(session);
    Ok(())
}

fn main() -> ExitCode {
    let args = Args::parse();
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    // First Ctrl-C ends the frame loop cleanly (daemon stopped, exit 0); a second one, for a
    // script stuck in a loop of its own, exits at once.
    let _ = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::Relaxed) {
            std::process::exit(130);
        }
    });
    match run(&args, &stop) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("physics-lua: {message}");
            ExitCode::FAILURE
        }
    }
}
