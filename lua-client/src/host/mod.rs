//! The host side of the API: the frame loop ([`Host`]), the scheduler behind `wait` and
//! coroutines, signals, the watchdog that stops runaway scripts, and errors as scripts see
//! them. Nothing here knows an API type: what changes per frame (a simulated part's CFrame)
//! is [`Watched`] through a trait object.

pub mod assets;
pub mod errors;
pub(crate) mod identity;
pub mod scheduler;
pub mod signal;
pub mod watchdog;
pub mod watched;

use std::rc::Rc;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

use client_sdk::Client;
use mlua::{Function, Lua, MultiValue, Value};

use crate::values::sdk_error;
use scheduler::Scheduler;
use signal::Signal;
pub use watchdog::Stop;
pub use watched::{DaemonWatch, Watched};

/// The longest a host should sleep between frames while [`Host::watching_daemon`].
pub const WATCH_PERIOD: Duration = Duration::from_millis(100);

/// A host's handle on the installed API: drives frames.
pub struct Host {
    lua: Lua,
    scheduler: Rc<Scheduler>,
    /// The global `Heart` signal, fired once per frame with dt.
    heart: Signal,
    client: Client,
    daemon: Rc<dyn DaemonWatch>,
}

impl Host {
    /// The handle `install` returns for `lua`.
    pub(crate) fn new(
        lua: &Lua,
        scheduler: Rc<Scheduler>,
        heart: Signal,
        client: Client,
        daemon: Rc<dyn DaemonWatch>,
    ) -> Host {
        Host {
            lua: lua.clone(),
            scheduler,
            heart,
            client,
            daemon,
        }
    }

    /// Runs `f` as a script thread: until it finishes or first waits.
    pub fn spawn(&self, f: Function) -> mlua::Result<()> {
        scheduler::spawn(&self.lua, f, MultiValue::new())
    }

    /// One frame of `dt` seconds, ending with the flush of every write it made.
    pub fn frame(&self, dt: f64) -> mlua::Result<()> {
        // Reads in this frame take each plane's newest sample once.
        self.client.begin_frame();
        for c in self.daemon.placed() {
            c.begin_frame();
        }
        self.daemon.watch(&self.lua)?;
        self.scheduler.frame(&self.lua)?;
        self.heart
            .fire(&self.lua, MultiValue::from_iter([Value::Number(dt)]))?;
        self.flush()
    }

    /// Whether the script listens to `PhysicsService.Stalled` / `Resumed`: the host then
    /// runs a frame at least every [`WATCH_PERIOD`] while the script only waits.
    pub fn watching_daemon(&self) -> bool {
        self.daemon.watching()
    }

    /// Sends the queued writes as one request.
    pub fn flush(&self) -> mlua::Result<()> {
        for c in std::iter::once(self.client.clone()).chain(self.daemon.placed()) {
            c.flush()
                .map_err(|e| sdk_error("the physics daemon rejected a write", e))?;
        }
        Ok(())
    }

    /// Whether frames still have work: `Heart` handlers, pending waits, or change listeners.
    pub fn busy(&self) -> bool {
        self.heart.listeners() > 0
            || self.scheduler.pending_waits() > 0
            || self.scheduler.change_listeners()
    }

    /// Whether the next frame is needed regardless of waits (Heart or change listeners).
    pub fn busy_every_frame(&self) -> bool {
        self.heart.listeners() > 0 || self.scheduler.change_listeners()
    }

    /// Seconds until the earliest pending `wait` is due.
    pub fn next_wake_in(&self) -> Option<f64> {
        self.scheduler.next_wake_in()
    }

    /// The client the API talks to the daemon through.
    pub fn client(&self) -> &Client {
        &self.client
    }

    /// Stops a script that runs longer than `max` without yielding back to the host (a
    /// `wait`, the end of the main chunk or of a handler) with an error naming the limit.
    /// Wall-clock time, API calls included. `None`: no limit.
    pub fn set_max_run_time(&self, max: Option<Duration>) {
        self.scheduler.watchdog.set_max_run(max);
    }

    /// Limits the memory of the Lua state to `bytes`: an allocation past it raises Lua's
    /// "not enough memory" error. `None`: no limit.
    pub fn set_memory_limit(&self, bytes: Option<usize>) -> mlua::Result<()> {
        self.lua.set_memory_limit(bytes.unwrap_or(0)).map(|_| ())
    }

    /// Stops a script still running at `at` (`None`: no deadline). The host's own loop
    /// should not start frames past it.
    pub fn set_deadline(&self, at: Option<Instant>) {
        self.scheduler.watchdog.set_deadline(at);
    }

    /// Stops a running script once `flag` is set, from any thread (a signal handler).
    pub fn set_stop_flag(&self, flag: Arc<AtomicBool>) {
        self.scheduler.watchdog.set_stop_flag(flag);
    }

    /// Why the watchdog stopped a script, if it did.
    pub fn stopped(&self) -> Option<Stop> {
        self.scheduler.watchdog.stopped()
    }
}
