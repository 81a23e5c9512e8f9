//! The watchdog: a Luau interrupt that stops a script which runs too long without yielding
//! back to the host, is still running when the host's deadline passes, or that the host was
//! asked to stop (a signal). Luau calls the interrupt at loop back-edges and function calls,
//! so even `while true do end` is stopped; a call into a long C function (a huge
//! `table.sort`) is stopped when it returns.

use std::cell::{Cell, RefCell};
use std::fmt;
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use mlua::{Lua, VmState};

/// The clock is read once per this many interrupts (reading it every time would cost more
/// than the interrupt itself); the stop flag is read every time.
const CLOCK_EVERY: u32 = 256;

/// Why the watchdog stopped the script.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// The script ran longer than `limit` without yielding back to the host.
    RunTime {
        /// The limit it ran past.
        limit: Duration,
    },
    /// The host's deadline passed while the script was running.
    Deadline,
    /// The host was asked to stop (its stop flag was set, e.g. by a signal).
    Requested,
}

impl fmt::Display for Stop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Stop::RunTime { limit } => write!(
                f,
                "script ran {} ms without yielding to the host (limit: {0} ms)",
                limit.as_millis()
            ),
            Stop::Deadline => {
                f.write_str("the run's time limit passed while the script was running")
            }
            Stop::Requested => f.write_str("the run was stopped while the script was running"),
        }
    }
}

/// The watchdog's state, shared by the scheduler (which marks when scripts run) and the
/// interrupt (which checks).
pub struct Watchdog {
    max_run: Cell<Option<Duration>>,
    deadline: Cell<Option<Instant>>,
    stop: RefCell<Option<Arc<AtomicBool>>>,
    /// When the outermost running resume began; `None` while the host itself runs.
    running_since: Cell<Option<Instant>>,
    depth: Cell<u32>,
    calls: Cell<u32>,
    /// Once tripped, every further interrupt raises again, so a script that catches the
    /// error with `pcall` cannot keep running.
    tripped: Cell<Option<Stop>>,
}

impl Watchdog {
    /// No limits, no deadline, no stop flag.
    pub fn new() -> Watchdog {
        Watchdog {
            max_run: Cell::new(None),
            deadline: Cell::new(None),
            stop: RefCell::new(None),
            running_since: Cell::new(None),
            depth: Cell::new(0),
            calls: Cell::new(0),
            tripped: Cell::new(None),
        }
    }

    /// Installs the interrupt that enforces the watchdog in `lua`.
    pub fn install(self: &Rc<Self>, lua: &Lua) {
        let dog = self.clone();
        lua.set_interrupt(move |lua| match dog.check() {
            None => Ok(VmState::Continue),
            Some(stop) => Err(mlua::Error::runtime(format!("{}{stop}", position(lua)))),
        });
    }

    /// The longest a script may run without yielding back to the host (`None`: no limit).
    pub fn set_max_run(&self, max: Option<Duration>) {
        self.max_run.set(max);
    }

    /// Scripts still running at `at` are stopped (`None`: no deadline).
    pub fn set_deadline(&self, at: Option<Instant>) {
        self.deadline.set(at);
    }

    /// Scripts are stopped once `flag` is set (from any thread, e.g. a signal handler).
    pub fn set_stop_flag(&self, flag: Arc<AtomicBool>) {
        *self.stop.borrow_mut() = Some(flag);
    }

    /// Why the watchdog stopped a script, if it did.
    pub fn stopped(&self) -> Option<Stop> {
        self.tripped.get()
    }

    /// Marks that the host hands control to a script (resumes a coroutine) until the guard
    /// drops. Nested resumes (a handler fired from inside a script) count as one run.
    pub fn running(self: &Rc<Self>) -> Running {
        if self.depth.get() == 0 {
            self.running_since.set(Some(Instant::now()));
            // A run-time trip ends with the run that caused it; a deadline or a stop request
            // holds for good.
            if matches!(self.tripped.get(), Some(Stop::RunTime { .. })) {
                self.tripped.set(None);
            }
        }
        self.depth.set(self.depth.get() + 1);
        Running(self.clone())
    }

    fn check(&self) -> Option<Stop> {
        if let Some(stop) = self.tripped.get() {
            return Some(stop);
        }
        let requested = self.stop_requested();
        let stop = if requested {
            Some(Stop::Requested)
        } else {
            let calls = self.calls.get().wrapping_add(1);
            self.calls.set(calls);
            if !calls.is_multiple_of(CLOCK_EVERY) {
                return None;
            }
            self.overdue(Instant::now())
        };
        if stop.is_some() {
            self.tripped.set(stop);
        }
        stop
    }

    fn stop_requested(&self) -> bool {
        self.stop
            .borrow()
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    }

    fn overdue(&self, now: Instant) -> Option<Stop> {
        if self.deadline.get().is_some_and(|d| now >= d) {
            return Some(Stop::Deadline);
        }
        match (self.running_since.get(), self.max_run.get()) {
            (Some(since), Some(limit)) if now.duration_since(since) >= limit => {
                Some(Stop::RunTime { limit })
            }
            _ => None,
        }
    }
}

/// While alive, a script runs (see [`Watchdog::running`]).
pub struct Running(Rc<Watchdog>);

impl Drop for Running {
    fn drop(&mut self) {
        let depth = self.0.depth.get() - 1;
        self.0.depth.set(depth);
        if depth == 0 {
            self.0.running_since.set(None);
        }
    }
}

/// `source:line: ` of the Lua code running now, as `error("...")` would prefix it.
fn position(lua: &Lua) -> String {
    lua.inspect_stack(0, |d| {
        let line = d.current_line()?;
        let src = d.source().short_src?.into_owned();
        Some(format!("{src}:{line}: "))
    })
    .flatten()
    .unwrap_or_default()
}
